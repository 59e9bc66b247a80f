#include "ViewportWindow.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <QExposeEvent>
#include <QMetaObject>
#include <QKeyEvent>
#include <QMouseEvent>
#include <QVulkanInstance>
#include <QWheelEvent>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "lpv/Lpv.h"

namespace terralux {

ViewportWindow::ViewportWindow(vk::VulkanContext& ctx, QVulkanInstance* instance)
    : ctx_(ctx),
      resolution_(ctx.deviceType() == VK_PHYSICAL_DEVICE_TYPE_CPU ? kCpuFrameBudgetMs : kGpuFrameBudgetMs) {
    setSurfaceType(QSurface::VulkanSurface);
    setVulkanInstance(instance);
    refineTimer_.setSingleShot(true);
    refineTimer_.setInterval(kRefineDelayMs);
    connect(&refineTimer_, &QTimer::timeout, this, [this] {
        refining_ = true;
        requestUpdate();
    });
    presentPoll_.setInterval(2);
    connect(&presentPoll_, &QTimer::timeout, this, &ViewportWindow::pollPresent);
    // A sun edit's horizon map is swept, and a new camera's levels of detail chosen, on a worker:
    // once either has finished, a frame takes it. The full-resolution frame due after the change
    // does; with none due, the frame that takes it is one (the view holds still), not another
    // frame of the change.
    workerPoll_.setInterval(10);
    connect(&workerPoll_, &QTimer::timeout, this, [this] {
        const TerrainRenderer* t = renderer_ ? &renderer_->renderer() : nullptr;
        if (!t || (!t->sunHorizonSweeping() && !t->levelOfDetailBuilding())) {
            workerPoll_.stop();
        } else if (t->sunHorizonSwept() || t->levelOfDetailBuilt()) {
            workerPoll_.stop();
            if (refineTimer_.isActive()) return;
            refining_ = true;
            requestUpdate();
        }
    });
    // A frame put off for its pipelines or its first meter reading is asked for again once they
    // are there.
    deferredPoll_.setInterval(10);
    connect(&deferredPoll_, &QTimer::timeout, this, [this] {
        if (renderer_ && renderer_->waitingToDraw()) return;
        deferredPoll_.stop();
        requestUpdate();
    });
}

void ViewportWindow::setDynamicResolution(bool on) {
    dynamicResolution_ = on;
    requestUpdate();
}

ViewportWindow::~ViewportWindow() {
    stopLpv();
    swapchain_.reset();
}

void ViewportWindow::setRenderer(ProjectRenderer* renderer) {
    stopLpv();  // the worker reads the old renderer's terrain
    renderer_ = renderer;
    requestUpdate();
}

void ViewportWindow::setCamera(const OrbitCamera& camera) {
    camera_ = camera;
    requestUpdate();
}

void ViewportWindow::setDebugView(int view) {
    request_.debugView = view;
    requestUpdate();
}

void ViewportWindow::setProbeLighting(bool on) {
    request_.probes = on;
    requestUpdate();
}

void ViewportWindow::setProbePositions(bool on) {
    request_.probePositions = on;
    requestUpdate();
}

void ViewportWindow::setLeaves(bool on) {
    request_.leaves = on;
    requestUpdate();
}

void ViewportWindow::setWaterTime(double seconds) {
    if (request_.time == seconds) return;
    request_.time = seconds;
    requestUpdate();
}

void ViewportWindow::exposeEvent(QExposeEvent*) {
    if (isExposed()) renderNow();
}

bool ViewportWindow::event(QEvent* e) {
    if (e->type() == QEvent::UpdateRequest) {
        draw(false);
        return true;
    }
    return QWindow::event(e);
}

void ViewportWindow::updateSize() {
    const qreal dpr = devicePixelRatio();
    request_.width = uint32_t(std::max(1, int(width() * dpr)));
    request_.height = uint32_t(std::max(1, int(height() * dpr)));
}

void ViewportWindow::stopLpv() {
    lpvJob_.stop();
    lpvBusy_ = false;
    lpvSchedule_.reset();
}

bool ViewportWindow::lpvCurrent() {
    if (!renderer_) return true;
    const std::optional<LpvJob> job = renderer_->lpvJob(request_, camera_);
    return !job || job->key == renderer_->lpvKey();
}

void ViewportWindow::scheduleLpv() {
    std::optional<LpvJob> job = renderer_->lpvJob(request_, camera_);
    if (!job) return;
    // Volumes started for this key that are not bound now were dropped (the LPV was off for a
    // while): they are wanted again.
    if (!lpvBusy_ && lpvSchedule_.startedFor(job->key) && renderer_->lpvKey() != job->key) lpvSchedule_.reset();
    lpvSchedule_.setInterval(job->settings.updateInterval);
    if (!lpvSchedule_.frame(job->key, lpvBusy_)) {
        // A change waiting for its frame needs frames to come.
        if (lpvSchedule_.pending() && !lpvBusy_) requestUpdate();
        return;
    }
    lpvBusy_ = true;
    // The one before has finished: its result has landed.
    lpvJob_.start([this, job = std::move(*job)](const LatestJob::Context& context) {
        const auto start = std::chrono::steady_clock::now();
        std::shared_ptr<const lpv::Volumes> volumes;
        try {
            volumes = job.run();
        } catch (const std::exception&) {
            // Settings the volumes refuse draw none; the next change tries again.
        }
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        context.post([this, volumes, key = job.key, ms] {
            lpvBusy_ = false;
            if (!renderer_) return;
            renderer_->setLpv(volumes, key);
            emit lpvUpdated(ms);
            requestUpdate();
        });
    });
}

void ViewportWindow::renderNow() { draw(true); }

void ViewportWindow::draw(bool now) {
    if (!renderer_ || !isExposed()) return;
    if (swapchain_ && swapchain_->pending()) {
        if (now) swapchain_->waitForHeld();
        pollPresent();
        if (swapchain_->pending()) {
            // The last frame is not on screen yet: this one is drawn when it is (pollPresent). A
            // change asked for meanwhile puts the full-resolution frame off, as a drawn one does.
            frameWanted_ = true;
            if (!refining_ && refineTimer_.isActive()) refineTimer_.start();
            presentPoll_.start();
            return;
        }
    }
    scheduleLpv();
    const auto start = std::chrono::steady_clock::now();
    updateSize();
    if (!swapchain_) {
        VkSurfaceKHR surface = QVulkanInstance::surfaceForWindow(this);
        if (!surface) return;
        swapchain_ = std::make_unique<vk::Swapchain>(ctx_, surface);
        // A CPU device presents in software, waiting for the frame: present finished frames only.
        swapchain_->setHoldsFrames(ctx_.deviceType() == VK_PHYSICAL_DEVICE_TYPE_CPU);
    }
    request_.gizmos = interaction_ ? interaction_->gizmos(camera_, QSizeF(width(), height())) : std::vector<GizmoLine>{};
    // A frame of a change draws at the scale that holds the budget; the full-resolution frame
    // follows when the changes stop.
    const double scale = dynamicResolution_ && !refining_ ? resolution_.interactiveScale() : 1.0;
    const bool refining = refining_;
    refining_ = false;
    RenderRequest drawn = request_;
    const ScaledSize size = scaledSize(request_.width, request_.height, scale);
    drawn.width = size.width;
    drawn.height = size.height;
    drawn.levelOfDetailRows = request_.height;
    drawn.windowWidth = request_.width;
    drawn.windowHeight = request_.height;
    drawn.waitForHorizon = false;
    drawn.waitForLevelOfDetail = false;
    drawn.waitUntilDrawable = false;
    // Below full resolution the refine timer below brings the full-resolution frame, which meters.
    drawn.interactive = size.width < request_.width || size.height < request_.height;
    if (!renderer_->present(drawn, camera_, *swapchain_)) {
        // Its pipelines are compiling on a worker, or its first meter is being drawn: the frame
        // is drawn, as it was asked for, once they are done.
        if (renderer_->deferredFrame()) {
            refining_ = refining;
            deferredPoll_.start();
        }
        return;
    }
    if (renderer_->renderer().sunHorizonSweeping() || renderer_->renderer().levelOfDetailBuilding()) workerPoll_.start();
    drawnScale_ = std::sqrt(double(drawn.width) * drawn.height / (double(request_.width) * request_.height));
    if (drawnScale_ < 1.0) refineTimer_.start();
    else refineTimer_.stop();
    frameStart_ = start;
    presentPoll_.start();
    pollPresent();
}

void ViewportWindow::pollPresent() {
    if (!swapchain_ || !swapchain_->presentIfDone()) return;
    presentPoll_.stop();
    if (!frameStart_) return;
    // The frame's wall time from its recording to its presentation.
    const auto ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - *frameStart_).count();
    frameStart_.reset();
    presentedScale_ = drawnScale_;
    const bool wanted = frameWanted_;
    frameWanted_ = false;
    if (!renderer_) return;
    // The frame last known finished (this slot's previous one): its GPU time where timed, at the
    // scale it was drawn at.
    const FrameTimings& t = renderer_->renderer().lastFrameTimings();
    if (t.gpuTimed() && t.width > 0 && t.height > 0)
        resolution_.frameFinished(t.gpuMilliseconds,
                                  std::min(1.0, std::sqrt(double(t.width) * t.height / (double(request_.width) * request_.height))));
    else if (!t.gpuTimed())
        resolution_.frameFinished(ms, presentedScale_);
    if (renderer_->exposureAdapting() || wanted) requestUpdate();  // the eye has not yet adapted, or a change waits
    emit frameRendered(ms);
}

RenderedImage ViewportWindow::grabImage(bool gizmos) {
    if (!renderer_) return {};
    updateSize();
    request_.gizmos = gizmos && interaction_ ? interaction_->gizmos(camera_, QSizeF(width(), height()))
                                             : std::vector<GizmoLine>{};
    return renderer_->render(request_, camera_);
}

void ViewportWindow::orbit(float dAz, float dEl) {
    camera_.azimuthDeg = std::fmod(camera_.azimuthDeg + dAz + 360.0f, 360.0f);
    camera_.elevationDeg = std::clamp(camera_.elevationDeg + dEl, -89.0f, 89.0f);
    emit cameraChanged();
    requestUpdate();
}

void ViewportWindow::pan(float dx, float dy) {
    // Move the target in the view plane, scaled so the terrain follows the cursor roughly.
    const glm::vec3 forward = glm::normalize(camera_.target - camera_.position());
    const glm::vec3 right = glm::normalize(glm::cross(forward, glm::vec3(0.0f, 1.0f, 0.0f)));
    const glm::vec3 up = glm::cross(right, forward);
    const float scale = camera_.radius * std::tan(glm::radians(0.5f * camera_.fovDeg)) * 2.0f /
                        float(std::max(1, height()));
    camera_.target += (-dx * right + dy * up) * scale;
    emit cameraChanged();
    requestUpdate();
}

void ViewportWindow::zoom(float factor) {
    camera_.radius = std::clamp(camera_.radius * factor, 1.0f, 1e8f);
    emit cameraChanged();
    requestUpdate();
}

void ViewportWindow::setInteraction(ViewportInteraction* interaction) {
    if (grabbing_ && interaction_) interaction_->release(true);
    grabbing_ = false;
    interaction_ = interaction;
    requestUpdate();
}

void ViewportWindow::mousePressEvent(QMouseEvent* e) {
    lastMouse_ = pressedAt_ = e->position();
    dragged_ = false;
    grabbing_ = e->button() == Qt::LeftButton && !(e->modifiers() & Qt::ShiftModifier) && interaction_ &&
                interaction_->grab(e->position(), camera_, QSizeF(width(), height()));
    if (grabbing_) requestUpdate();
}

void ViewportWindow::mouseReleaseEvent(QMouseEvent* e) {
    if (grabbing_ && e->button() == Qt::LeftButton) {
        grabbing_ = false;
        interaction_->release(false);
        requestUpdate();
        // A press on a handle that did not move is still a click (it selects what is under it).
        if (!dragged_) emit clicked(e->position());
        return;
    }
    if (e->button() == Qt::LeftButton && !dragged_) emit clicked(e->position());
}

void ViewportWindow::mouseMoveEvent(QMouseEvent* e) {
    if (grabbing_) {
        if ((e->position() - pressedAt_).manhattanLength() > 4.0) dragged_ = true;
        if (dragged_) interaction_->drag(e->position(), camera_, QSizeF(width(), height()));
        requestUpdate();
        return;
    }
    // A few pixels of jitter in a click are not an orbit.
    if ((e->position() - pressedAt_).manhattanLength() > 4.0) dragged_ = true;
    const QPointF d = e->position() - lastMouse_;
    lastMouse_ = e->position();
    const bool panning = (e->buttons() & Qt::MiddleButton) ||
                         ((e->buttons() & Qt::LeftButton) && (e->modifiers() & Qt::ShiftModifier));
    if (panning) pan(float(d.x()), float(d.y()));
    else if (e->buttons() & Qt::LeftButton) orbit(float(d.x()) * 0.3f, float(d.y()) * 0.3f);
}

void ViewportWindow::wheelEvent(QWheelEvent* e) {
    zoom(std::pow(0.999f, float(e->angleDelta().y())));
}

void ViewportWindow::keyPressEvent(QKeyEvent* e) {
    if (grabbing_ && e->key() == Qt::Key_Escape) {
        grabbing_ = false;
        interaction_->release(true);
        requestUpdate();
        return;
    }
    switch (e->key()) {
        case Qt::Key_Left: orbit(-5.0f, 0.0f); break;
        case Qt::Key_Right: orbit(5.0f, 0.0f); break;
        case Qt::Key_Up: orbit(0.0f, 5.0f); break;
        case Qt::Key_Down: orbit(0.0f, -5.0f); break;
        case Qt::Key_Plus:
        case Qt::Key_Equal: zoom(0.9f); break;
        case Qt::Key_Minus: zoom(1.0f / 0.9f); break;
        case Qt::Key_W: pan(0.0f, 20.0f); break;
        case Qt::Key_S: pan(0.0f, -20.0f); break;
        case Qt::Key_A: pan(20.0f, 0.0f); break;
        case Qt::Key_D: pan(-20.0f, 0.0f); break;
        case Qt::Key_F:
        case Qt::Key_Home:
            if (renderer_) setCamera(renderer_->defaultCamera());
            emit cameraChanged();
            break;
        default: QWindow::keyPressEvent(e);
    }
}

}  // namespace terralux
