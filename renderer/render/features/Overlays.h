#pragma once
// The overlays drawn over the lit frame: probe markers, reflection-probe markers and the octree
// leaves.

#include "render/Frame.h"

namespace terralux::features {

// The probe markers' and octree leaves' overlay.
blocks::OverlayBlock packOverlay(const RenderSettings& s, float smallestLeaf, float smallestLeafPixels);
void addOverlayPass(Frame& f);

}  // namespace terralux::features
