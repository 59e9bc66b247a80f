#pragma once
// The overlays drawn over the lit frame: probe markers, reflection-probe markers, the octree
// leaves and the gizmo lines (volume bounds and handles).

#include <vector>

#include "render/Frame.h"

namespace terralux::features {

// The probe markers' and octree leaves' overlay.
// One gizmo line as shaders/gizmos.vert reads it: its two ends and its colour.
struct GizmoInstance {
    glm::vec4 a, b, color;
};
std::vector<GizmoInstance> packGizmos(const std::vector<GizmoLine>& lines);

// A probe marker's half width on screen, in output pixels.
inline constexpr float kMarkerPixels = 3.0f;
// `pixelScale`: the drawn frame's pixels per output pixel along a side (2 under ssaa).
blocks::OverlayBlock packOverlay(const RenderSettings& s, float smallestLeaf, float smallestLeafPixels,
                                 float pixelScale);
void addOverlayPass(Frame& f);

}  // namespace terralux::features
