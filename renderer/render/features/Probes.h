#pragma once
// Diffuse probe volumes: the baked grids on the GPU and the compute pass that evaluates them at
// every terrain vertex (the probe light the terrain pass reads as a vertex attribute).

#include "render/Frame.h"

namespace terralux {

// Present only while volumes are bound.
struct ProbeResources {
    vk::Buffer block, coeffs, cells, volumes, errors, light;
    vk::DescriptorSet set;
    bool lightStale = true;  // the probe pass has not run since the volumes changed
};

namespace features {

// Evaluates the volumes at the vertices, once after they changed.
void addProbePass(Frame& f);

}  // namespace features
}  // namespace terralux
