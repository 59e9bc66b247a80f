#pragma once
// The live viewport: a Vulkan window that presents the renderer's offscreen image (the same
// draw as `terralux --render`) with frames in flight, never reading pixels back or waiting for
// the GPU per frame; an orbit camera on the mouse and keys.
//   left drag: orbit   middle drag or shift + left drag: pan   wheel: zoom   left click: pick
//   arrows: orbit   +/-: zoom   W/A/S/D: pan   F or Home: frame the terrain

#include <chrono>
#include <memory>
#include <optional>
#include <vector>

#include <QTimer>
#include <QWindow>

#include "LatestJob.h"
#include "ProjectRenderer.h"
#include "lpv/UpdateSchedule.h"
#include "scene/DynamicResolution.h"
#include "scene/OrbitCamera.h"
#include "vk/Swapchain.h"

class QVulkanInstance;

namespace terralux {

// What the pointer can grab before it orbits (ViewportGizmos): a left press that grab() takes
// drags it until release instead of moving the camera, and Escape cancels that drag. Its lines
// are drawn over every frame.
class ViewportInteraction {
public:
    virtual ~ViewportInteraction() = default;
    // `size`: the viewport in logical pixels.
    virtual bool grab(QPointF at, const OrbitCamera& camera, QSizeF size) = 0;
    virtual void drag(QPointF at, const OrbitCamera& camera, QSizeF size) = 0;
    virtual void release(bool cancelled) = 0;
    virtual std::vector<GizmoLine> gizmos(const OrbitCamera& camera, QSizeF size) const = 0;
};

class ViewportWindow : public QWindow {
    Q_OBJECT
public:
    ViewportWindow(vk::VulkanContext& ctx, QVulkanInstance* instance);
    ~ViewportWindow() override;

    // The renderer to draw with (owned by the caller; may be replaced or cleared).
    void setRenderer(ProjectRenderer* renderer);
    // Handles the pointer may grab and lines drawn over the frame (owned by the caller; null: none).
    void setInteraction(ViewportInteraction* interaction);
    bool grabbing() const { return grabbing_; }
    void setCamera(const OrbitCamera& camera);
    const OrbitCamera& camera() const { return camera_; }
    void setDebugView(int view);
    int debugView() const { return request_.debugView; }
    void setProbeLighting(bool on);
    void setProbePositions(bool on);
    void setLeaves(bool on);
    // Seconds into the water's wave animation (the Water dock's time slider and Play).
    void setWaterTime(double seconds);
    double waterTime() const { return request_.time; }
    // Draws the current view again and reads it back (row 0 at the top), waiting for the GPU:
    // for tests and screenshots, never per frame. Without `gizmos`, the frame alone, as
    // `terralux --render` draws it; with them, the bounds and handles over it as on screen.
    RenderedImage grabImage(bool gizmos = false);
    // Records and submits a frame now instead of at the next update, waiting for the frame
    // before it to finish if it has not (the updates the viewport asks for itself never wait).
    void renderNow();
    // The light propagation volumes: each frame that draws them asks the schedule
    // (lpv.update_interval in frames) whether to start an update for its camera and settings; the
    // update runs on a worker and lands on this thread, and frames draw the last volumes bound.
    const lpv::UpdateSchedule& lpvSchedule() const { return lpvSchedule_; }
    bool lpvUpdating() const { return lpvBusy_; }
    // Whether the bound volumes are those the current view and camera want (or none are wanted).
    bool lpvCurrent();
    ProjectRenderer* renderer() const { return renderer_; }
    // Waits for the update under way and drops its result.
    void stopLpv();

    // Dynamic resolution (docs/ARCHITECTURE.md, "Dynamic resolution"): while the view changes,
    // frames are drawn at the scale that holds the frame budget (measured by the frame graph's
    // GPU time, or the wall time where the device has no timestamps) and blitted up to the
    // window; kRefineDelayMs after the last change one frame at full resolution follows. Off:
    // every frame at full resolution.
    static constexpr int kRefineDelayMs = 250;
    // The budget: 100 ms on a CPU device (lavapipe), a 60 Hz frame on a GPU.
    static constexpr double kCpuFrameBudgetMs = 100.0, kGpuFrameBudgetMs = 1000.0 / 60.0;
    void setDynamicResolution(bool on);
    bool dynamicResolution() const { return dynamicResolution_; }
    void setFrameBudget(double milliseconds) { resolution_.setBudgetMilliseconds(milliseconds); }
    const DynamicResolution& resolution() const { return resolution_; }
    // The scale of the last frame presented: its pixels over the window's, square-rooted.
    double presentedScale() const { return presentedScale_; }
    // Whether a frame is submitted and not yet presented, asked for, or due (the full-resolution
    // frame after a change, the frame that takes a horizon map swept on a worker): the viewport
    // has more to show.
    bool drawing() const {
        return presentPoll_.isActive() || frameWanted_ || refineTimer_.isActive() || workerPoll_.isActive() ||
               deferredPoll_.isActive();
    }

signals:
    // A frame reached the window: the wall time from its recording to its presentation (on a
    // CPU device, which holds a frame until it is drawn, the device's time and the wait for the
    // next poll included).
    void frameRendered(double milliseconds);
    void cameraChanged();
    // A left click that did not drag: `position` in the window's logical pixels.
    void clicked(QPointF position);
    // An LPV update landed: the volumes took `milliseconds` on the worker.
    void lpvUpdated(double milliseconds);

protected:
    void exposeEvent(QExposeEvent*) override;
    bool event(QEvent* e) override;
    void mousePressEvent(QMouseEvent* e) override;
    void mouseMoveEvent(QMouseEvent* e) override;
    void mouseReleaseEvent(QMouseEvent* e) override;
    void wheelEvent(QWheelEvent* e) override;
    void keyPressEvent(QKeyEvent* e) override;

private:
    void updateSize();
    // Draws a frame; when the one before is not presented yet, waits for it (`now`) or draws
    // once it is.
    void draw(bool now);
    // Presents the submitted frame once the device has finished it, then finishes its accounting.
    void pollPresent();
    void scheduleLpv();
    void orbit(float dAzimuth, float dElevation);
    void pan(float dx, float dy);
    void zoom(float factor);
    vk::VulkanContext& ctx_;
    ProjectRenderer* renderer_ = nullptr;
    std::unique_ptr<vk::Swapchain> swapchain_;
    OrbitCamera camera_;
    RenderRequest request_;
    QPointF lastMouse_, pressedAt_;
    bool dragged_ = false;
    ViewportInteraction* interaction_ = nullptr;
    bool grabbing_ = false;  // a left drag the interaction took
    lpv::UpdateSchedule lpvSchedule_;
    LatestJob lpvJob_{this};
    bool lpvBusy_ = false;  // UI thread only: set when a worker starts, cleared when its result lands
    DynamicResolution resolution_;
    bool dynamicResolution_ = true;
    bool refining_ = false;       // the next frame is the full-resolution one after the changes
    double presentedScale_ = 1.0;
    double drawnScale_ = 1.0;  // of the frame submitted last, presented or not
    QTimer refineTimer_;
    // The UI thread never waits for the device: a submitted frame is presented once it has
    // finished (polled every few milliseconds), and a frame asked for meanwhile is drawn then.
    QTimer presentPoll_;
    QTimer deferredPoll_;  // while a frame waits for its pipelines or its first meter (ProjectRenderer::waitingToDraw)
    QTimer workerPoll_;  // while the renderer sweeps a horizon map or chooses levels on a worker
    std::optional<std::chrono::steady_clock::time_point> frameStart_;
    bool frameWanted_ = false;
};

}  // namespace terralux
