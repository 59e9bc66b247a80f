#include "ViewportGizmos.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "ProjectDocument.h"

namespace terralux {

namespace {

float terrainExtent(const Heightfield& hf) {
    return std::max({hf.maxX() - hf.minX(), hf.maxZ() - hf.minZ(), hf.maxHeight() - hf.minHeight(), 1.0f});
}

// Each kind in its own colour, the selected one brighter; handles white, the one dragged orange.
glm::vec3 colorOf(BoundsKind kind, bool selected) {
    glm::vec3 c{1.0f};
    switch (kind) {
        case BoundsKind::ProbeVolume: c = {0.45f, 0.75f, 1.0f}; break;
        case BoundsKind::ReflectionGrid: c = {0.75f, 0.45f, 1.0f}; break;
        case BoundsKind::LpvCascade: c = {0.35f, 0.95f, 0.45f}; break;
        case BoundsKind::Water: c = {0.1f, 0.85f, 0.9f}; break;
        case BoundsKind::Sun: c = {1.0f, 0.85f, 0.25f}; break;
    }
    return selected ? glm::mix(c, glm::vec3(1.0f), 0.5f) : 0.8f * c;
}
constexpr glm::vec3 kHandle{1.0f, 1.0f, 1.0f}, kActiveHandle{1.0f, 0.55f, 0.1f};
constexpr double kHandlePixels = 10.0;

void addBox(std::vector<GizmoLine>& out, const glm::vec3& lo, const glm::vec3& hi, const glm::vec3& color) {
    const bool flat = hi.y - lo.y <= 0.0f;
    auto corner = [&](int i) { return glm::vec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z); };
    // Edges join corners differing in one bit: x (1), y (2), z (4).
    for (int i = 0; i < 8; ++i)
        for (int bit : {1, 2, 4}) {
            if (i & bit) continue;
            if (flat && ((i & 2) || bit == 2)) continue;  // a flat box is its rectangle
            out.push_back({corner(i), corner(i | bit), color});
        }
}

double segmentDistance(QPointF p, QPointF a, QPointF b) {
    const QPointF ab = b - a, ap = p - a;
    const double len2 = QPointF::dotProduct(ab, ab);
    const double t = len2 > 0.0 ? std::clamp(QPointF::dotProduct(ap, ab) / len2, 0.0, 1.0) : 0.0;
    const QPointF q = a + t * ab;
    return std::hypot(p.x() - q.x(), p.y() - q.y());
}

}  // namespace

ScreenProjection::ScreenProjection(const OrbitCamera& c, QSizeF s, const Heightfield& hf) : camera(c), size(s) {
    const double aspect = s.height() > 0.0 ? s.width() / s.height() : 1.0;
    viewProj = c.viewProjection(float(aspect), terrainExtent(hf));
    inverse = glm::inverse(viewProj);
}

std::optional<QPointF> ScreenProjection::toScreen(const glm::vec3& p) const {
    const glm::vec4 c = viewProj * glm::vec4(p, 1.0f);
    if (c.w <= 0.0f) return std::nullopt;
    return QPointF((c.x / c.w * 0.5 + 0.5) * size.width(), (c.y / c.w * 0.5 + 0.5) * size.height());
}

ScreenProjection::Ray ScreenProjection::ray(QPointF at) const {
    // Vulkan clip space: depth 0 to 1 (reversed or not, the two planes bound the ray).
    const float x = float(2.0 * at.x() / size.width() - 1.0), y = float(2.0 * at.y() / size.height() - 1.0);
    const glm::vec4 n = inverse * glm::vec4(x, y, 0.0f, 1.0f), f = inverse * glm::vec4(x, y, 1.0f, 1.0f);
    glm::vec3 from = glm::vec3(n) / n.w, to = glm::vec3(f) / f.w;
    // From the end nearer the camera.
    if (glm::distance(from, camera.position()) > glm::distance(to, camera.position())) std::swap(from, to);
    Ray r;
    r.origin = from;
    r.length = glm::length(to - from);
    if (r.length > 0.0f) r.direction = (to - from) / r.length;
    return r;
}

float ScreenProjection::metresPerPixel(const glm::vec3& p) const {
    const glm::vec3 forward = glm::normalize(camera.target - camera.position());
    const float depth = std::max(glm::dot(p - camera.position(), forward), 1e-3f);
    return 2.0f * depth * std::tan(0.5f * camera.fovDeg * std::numbers::pi_v<float> / 180.0f) /
           float(std::max(size.height(), 1.0));
}

ViewportGizmos::ViewportGizmos(ProjectDocument* doc, QObject* parent) : QObject(parent), doc_(doc) {
    connect(doc_, &ProjectDocument::parametersChanged, this, [this](const QString& path) {
        // Only these sections move what is drawn (the sun is read per frame).
        static const char* const sections[] = {"probe_volumes", "reflection_probes", "water", "terrain"};
        bool moves = path.isEmpty();
        for (const char* s : sections) moves = moves || path.startsWith(s);
        if (moves) refresh();
        emit redraw();
    });
    connect(doc_, &ProjectDocument::terrainChanged, this, [this] {
        refresh();
        emit redraw();
    });
    refresh();
}

const Heightfield& ViewportGizmos::heightfield() const { return doc_->terrain().heightfield; }

void ViewportGizmos::setScenario(const std::string& name) {
    if (name == scenario_) return;
    if (drag_) release(true);
    scenario_ = name;
    emit redraw();
}

SceneDescription ViewportGizmos::litScene() const {
    const SceneDescription& scene = doc_->project().scene;
    return scenarioScene(scene, knownScenario(scene, scenario_));
}

void ViewportGizmos::refresh() {
    try {
        scene_ = sceneBounds(doc_->project().scene, heightfield());
    } catch (const std::exception&) {
        scene_.clear();
    }
    if (selected_ && selected_->kind != BoundsKind::Sun && selected_->kind != BoundsKind::LpvCascade) {
        selected_ = find(selected_->kind, selected_->index);
        if (!selected_) emit selectionChanged({});
    }
}

std::optional<VolumeBounds> ViewportGizmos::find(BoundsKind kind, int index) const {
    for (const VolumeBounds& b : scene_)
        if (b.kind == kind && b.index == index) return b;
    return std::nullopt;
}

void ViewportGizmos::setShown(BoundsKind kind, bool shown) {
    shown_[size_t(kind)] = shown;
    if (!shown && selected_ && selected_->kind == kind) clearSelection();
    emit redraw();
}

std::vector<VolumeBounds> ViewportGizmos::bounds(const OrbitCamera& camera) const {
    std::vector<VolumeBounds> out;
    for (const VolumeBounds& b : scene_)
        if (shown(b.kind)) out.push_back(b);
    const SceneDescription scene = litScene();
    if (shown(BoundsKind::LpvCascade))
        for (const VolumeBounds& b : lpvBounds(scene, heightfield(), camera)) out.push_back(b);
    if (shown(BoundsKind::Sun))
        if (const auto sun = sunBounds(scene, heightfield(), camera, sunDistance(camera))) out.push_back(*sun);
    return out;
}

void ViewportGizmos::clearSelection() {
    if (!selected_) return;
    selected_.reset();
    emit selectionChanged({});
    emit redraw();
}

std::optional<VolumeBounds> ViewportGizmos::selectedFor(const OrbitCamera& camera) const {
    if (!selected_ || (selected_->kind != BoundsKind::Sun && selected_->kind != BoundsKind::LpvCascade)) return selected_;
    for (const VolumeBounds& b : bounds(camera))
        if (b.kind == selected_->kind && b.index == selected_->index) return b;
    return std::nullopt;
}

std::vector<Handle> ViewportGizmos::handles(const OrbitCamera& camera) const {
    const std::optional<VolumeBounds> b = selectedFor(camera);
    return b ? handlesOf(*b, litScene()) : std::vector<Handle>{};
}

bool ViewportGizmos::select(QPointF at, const OrbitCamera& camera, QSizeF size, double pixels, bool keepOnMiss) {
    const ScreenProjection view(camera, size, heightfield());
    std::optional<VolumeBounds> best;
    double bestDistance = pixels;
    auto consider = [&](const VolumeBounds& b, double d) {
        if (d < bestDistance) bestDistance = d, best = b;
    };
    // The selected bounds' handles first: a click on one keeps the selection.
    if (const std::optional<VolumeBounds> current = selectedFor(camera))
        for (const Handle& h : handlesOf(*current, litScene()))
            if (const auto p = view.toScreen(h.at)) consider(*current, std::hypot(p->x() - at.x(), p->y() - at.y()));
    for (const VolumeBounds& b : bounds(camera)) {
        if (b.kind == BoundsKind::Sun) {
            if (const auto p = view.toScreen(b.min)) consider(b, std::hypot(p->x() - at.x(), p->y() - at.y()));
            continue;
        }
        std::vector<GizmoLine> edges;
        addBox(edges, b.min, b.max, {});
        for (const GizmoLine& e : edges) {
            const auto a = view.toScreen(e.a), c = view.toScreen(e.b);
            if (a && c) consider(b, segmentDistance(at, *a, *c));
        }
    }
    if (!best) {
        if (!keepOnMiss) clearSelection();
        return false;
    }
    const bool changed = !selected_ || selected_->kind != best->kind || selected_->index != best->index;
    selected_ = best;
    if (changed) emit selectionChanged(QString::fromStdString(best->name));
    emit redraw();
    return true;
}

bool ViewportGizmos::grab(QPointF at, const OrbitCamera& camera, QSizeF size) {
    const std::optional<VolumeBounds> current = selectedFor(camera);
    if (!current) return false;
    const ScreenProjection view(camera, size, heightfield());
    std::optional<Handle> hit;
    double bestDistance = kHandlePixels;
    for (const Handle& h : handlesOf(*current, litScene()))
        if (const auto p = view.toScreen(h.at)) {
            const double d = std::hypot(p->x() - at.x(), p->y() - at.y());
            if (d < bestDistance) bestDistance = d, hit = h;
        }
    if (!hit) return false;
    drag_ = Drag{*current, *hit, litScene(), hit->at, {}};
    doc_->beginLiveEdit();
    emit redraw();
    return true;
}

void ViewportGizmos::drag(QPointF at, const OrbitCamera& camera, QSizeF size) {
    if (!drag_) return;
    const ScreenProjection view(camera, size, heightfield());
    const ScreenProjection::Ray ray = view.ray(at);
    const glm::vec3 o = ray.origin, d = ray.direction;
    glm::vec3 delta(0.0f);
    const Handle& h = drag_->handle;
    if (h.role == HandleRole::Sun) {
        // The pointer on the sphere the sun's point moves on: of its two crossings, the one nearer
        // the point; past the sphere's outline, the outline.
        const glm::vec3 centre = camera.target;
        const float radius = sunDistance(camera);
        const glm::vec3 oc = o - centre;
        const float b = glm::dot(oc, d), c = glm::dot(oc, oc) - radius * radius, disc = b * b - c;
        glm::vec3 p;
        if (disc >= 0.0f) {
            const glm::vec3 p0 = o + (-b - std::sqrt(disc)) * d, p1 = o + (-b + std::sqrt(disc)) * d;
            p = glm::distance(p0, h.at) <= glm::distance(p1, h.at) ? p0 : p1;
        } else {
            p = o - b * d;
        }
        if (glm::length(p - centre) <= 0.0f) return;
        delta = glm::normalize(p - centre);
    } else if (h.vertical()) {
        // The point of the vertical line through the handle nearest the pointer's ray.
        const glm::vec3 up(0.0f, 1.0f, 0.0f), w0 = h.at - o;
        const float b = glm::dot(up, d), denom = 1.0f - b * b;
        if (denom < 1e-6f) return;  // looking straight along the line
        const float s = (b * glm::dot(d, w0) - glm::dot(up, w0)) / denom;
        delta = glm::vec3(0.0f, s, 0.0f);
    } else {
        // The pointer on the horizontal plane through the handle.
        if (std::abs(d.y) < 1e-6f) return;
        const float t = (h.at.y - o.y) / d.y;
        if (t <= 0.0f) return;
        const glm::vec3 p = o + t * d;
        delta = glm::vec3(p.x - h.at.x, 0.0f, p.z - h.at.z);
    }
    try {
        HandleEdit edit = dragHandle(drag_->scene, heightfield(), drag_->bounds, h.role, delta);
        // A scenario's sun is its own rows.
        const SceneDescription& scene = doc_->project().scene;
        for (size_t i = 0; i < scene.scenarios.size(); ++i)
            if (scene.scenarios[i].name == scenario_)
                for (auto& value : edit.values)
                    if (value.first.rfind("sun.", 0) == 0) value.first = "scenarios[" + std::to_string(i) + "]." + value.first;
        QString error;
        if (!doc_->previewParameters(edit.values, &error)) {
            emit rejected(error);
            return;
        }
        drag_->label = QString::fromStdString(edit.label);
    } catch (const std::exception& e) {
        emit rejected(QString::fromStdString(e.what()));
    }
}

void ViewportGizmos::release(bool cancelled) {
    if (!drag_) return;
    const QString label = drag_->label;
    drag_.reset();
    if (cancelled || label.isEmpty()) doc_->cancelLiveEdit();
    else doc_->endLiveEdit(label);
    emit redraw();
}

std::vector<GizmoLine> ViewportGizmos::gizmos(const OrbitCamera& camera, QSizeF size) const {
    std::vector<GizmoLine> out;
    const std::vector<VolumeBounds> all = bounds(camera);
    if (all.empty()) return out;
    const ScreenProjection view(camera, size, heightfield());
    const glm::vec3 forward = glm::normalize(camera.target - camera.position());
    const glm::vec3 right = glm::normalize(glm::cross(forward, glm::vec3(0.0f, 1.0f, 0.0f)));
    const glm::vec3 up = glm::cross(right, forward);
    // A square facing the camera, `pixels` from its centre to a side.
    auto square = [&](const glm::vec3& at, float pixels, const glm::vec3& color) {
        const float m = pixels * view.metresPerPixel(at);
        const glm::vec3 r = m * right, u = m * up;
        const glm::vec3 c[4] = {at - r - u, at + r - u, at + r + u, at - r + u};
        for (int i = 0; i < 4; ++i) out.push_back({c[i], c[(i + 1) % 4], color});
    };
    for (const VolumeBounds& b : all) {
        const bool selected = selected_ && selected_->kind == b.kind && selected_->index == b.index;
        const glm::vec3 color = colorOf(b.kind, selected);
        if (b.kind == BoundsKind::Sun) {
            // A ring around the target at the sun's distance (the horizon it moves over), the line
            // toward the sun and the sun itself.
            const float radius = sunDistance(camera);
            constexpr int kSegments = 48;
            for (int i = 0; i < kSegments; ++i) {
                const float a0 = 2.0f * std::numbers::pi_v<float> * float(i) / kSegments;
                const float a1 = 2.0f * std::numbers::pi_v<float> * float(i + 1) / kSegments;
                out.push_back({camera.target + radius * glm::vec3(std::sin(a0), 0.0f, -std::cos(a0)),
                               camera.target + radius * glm::vec3(std::sin(a1), 0.0f, -std::cos(a1)), 0.5f * color});
            }
            // A dated sun moves along its day: the path, bright above the horizon.
            const std::vector<glm::vec3> path = sunPath(litScene(), heightfield(), camera, radius);
            for (size_t i = 1; i < path.size(); ++i) {
                const bool up = path[i - 1].y > camera.target.y || path[i].y > camera.target.y;
                out.push_back({path[i - 1], path[i], up ? 0.9f * color : 0.35f * color});
            }
            out.push_back({camera.target, b.min, color});
            out.push_back({camera.target, glm::vec3(b.min.x, camera.target.y, b.min.z), 0.5f * color});
            square(b.min, 7.0f, color);
        } else {
            addBox(out, b.min, b.max, color);
        }
        if (!selected) continue;
        const glm::vec3 top(0.5f * (b.min.x + b.max.x), b.max.y, 0.5f * (b.min.z + b.max.z));
        for (const Handle& h : handlesOf(b, litScene())) {
            const bool active = drag_ && drag_->handle.role == h.role;
            const glm::vec3 hc = active ? kActiveHandle : kHandle;
            if (h.role == HandleRole::Height && b.kind != BoundsKind::Water) out.push_back({top, h.at, hc});
            square(h.at, h.role == HandleRole::Move ? 7.0f : 5.0f, hc);
            if (h.role == HandleRole::Move) square(h.at, 3.0f, hc);
        }
    }
    return out;
}

}  // namespace terralux
