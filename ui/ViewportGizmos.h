#pragma once
// Volumes in the viewport: the bounds of the probe volumes, the reflection-probe grid, the LPV
// cascades, the water and the sun drawn over the frame (each kind shown or hidden), a click on
// one selects it, and the selected one's handles drag its settings (app/VolumeHandles.h says
// what each handle changes). A drag edits the document live, so the docks follow the pointer,
// and lands as one undo step with a human label.

#include <array>
#include <optional>
#include <vector>

#include <QObject>
#include <QPointF>
#include <QSizeF>
#include <QString>

#include <glm/mat4x4.hpp>

#include "ViewportWindow.h"
#include "VolumeHandles.h"

namespace terralux {

class ProjectDocument;

// The viewport's projection as the renderer draws it (TerrainRenderer: the far plane from the
// terrain box's largest side): points to logical pixels, pixels to rays.
struct ScreenProjection {
    ScreenProjection(const OrbitCamera& camera, QSizeF size, const Heightfield& hf);
    // None behind the camera.
    std::optional<QPointF> toScreen(const glm::vec3& p) const;
    // The pixel's ray from the near plane to the far plane.
    struct Ray {
        glm::vec3 origin{0.0f}, direction{0.0f, 0.0f, -1.0f};
        float length = 0.0f;
    };
    Ray ray(QPointF at) const;
    // Metres one pixel spans at `p`, across the view.
    float metresPerPixel(const glm::vec3& p) const;
    OrbitCamera camera;
    QSizeF size;
    glm::mat4 viewProj{1.0f}, inverse{1.0f};
};

class ViewportGizmos : public QObject, public ViewportInteraction {
    Q_OBJECT
public:
    explicit ViewportGizmos(ProjectDocument* doc, QObject* parent = nullptr);

    // The lighting scenario the viewport shows: the sun drawn and dragged is its sun, and a drag
    // writes that scenario's sun rows ("default": the project's own).
    void setScenario(const std::string& name);
    void setShown(BoundsKind kind, bool shown);
    bool shown(BoundsKind kind) const { return shown_[size_t(kind)]; }
    // What is drawn now: the shown kinds' bounds (LPV cascades around `camera`).
    std::vector<VolumeBounds> bounds(const OrbitCamera& camera) const;
    const std::optional<VolumeBounds>& selected() const { return selected_; }
    // A click at `at` (logical pixels): the shown bounds whose edge or handle is nearest within
    // `pixels` become the selection; nothing there clears it (unless `keepOnMiss`). Whether
    // something was hit.
    bool select(QPointF at, const OrbitCamera& camera, QSizeF size, double pixels = 8.0, bool keepOnMiss = false);
    void clearSelection();
    // The selected bounds as `camera` sees them now (the sun and the LPV cascades move with the
    // camera), and their handles.
    std::optional<VolumeBounds> selectedFor(const OrbitCamera& camera) const;
    std::vector<Handle> handles(const OrbitCamera& camera) const;

    // ViewportInteraction: a press on one of the selected bounds' handles starts a drag.
    bool grab(QPointF at, const OrbitCamera& camera, QSizeF size) override;
    void drag(QPointF at, const OrbitCamera& camera, QSizeF size) override;
    void release(bool cancelled) override;
    std::vector<GizmoLine> gizmos(const OrbitCamera& camera, QSizeF size) const override;
    bool dragging() const { return drag_.has_value(); }

signals:
    void selectionChanged(const QString& name);  // "" = none
    // A drag the rules refuse at this point (it keeps the last accepted values), or a sun that
    // cannot be dragged: one line for the status bar.
    void rejected(const QString& message);
    void redraw();

private:
    void refresh();  // the bounds from the document, after an edit or a new terrain
    const Heightfield& heightfield() const;
    std::optional<VolumeBounds> find(BoundsKind kind, int index) const;
    float sunDistance(const OrbitCamera& camera) const { return 0.35f * camera.radius; }
    // The project lit as the shown scenario (scenarioScene); the volumes are the project's.
    SceneDescription litScene() const;
    ProjectDocument* doc_;
    std::string scenario_ = "default";
    std::array<bool, kBoundsKinds> shown_{true, true, false, true, true};
    std::vector<VolumeBounds> scene_;  // sceneBounds of the document
    std::optional<VolumeBounds> selected_;
    struct Drag {
        VolumeBounds bounds;
        Handle handle;
        SceneDescription scene;  // as it was when the drag began: edits are from there
        glm::vec3 grabbed{0.0f};  // the point under the pointer on the handle's plane or line
        QString label;
    };
    std::optional<Drag> drag_;
};

}  // namespace terralux
