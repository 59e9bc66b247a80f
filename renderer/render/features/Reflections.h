#pragma once
// Reflection probes: the records and cubes of a bound set, and the grid block the lit passes
// read with the lights.

#include <memory>
#include <vector>

#include "render/Frame.h"

namespace terralux {

struct ReflectionProbeSet;  // bake/ReflectionBake.h

// Present only while a probe set is bound. The probe records and, for the cubemap encoding, their
// cubes (one cube-map array, layer 6·probe + face, with the set's mip chain; a 1×1 placeholder
// cube for the faces encoding) are uploaded once per set. The cubes are an image rather than
// texels in the buffer so that the sampler does the filtering the bake's evaluate() describes,
// bilinear (seamless across face edges, as cube-map hardware filters) and linear between mips,
// in one fetch per probe.
// Per frame slot: the grid block (it holds the live strength) and the lights sets that bind it,
// without and with the shadow cascades (the latter while the maps exist).
struct ReflectionResources {
    blocks::ReflectionBlock grid;
    vk::Buffer records, markers;
    vk::Image cubes;
    uint32_t markerCount = 0;
    std::vector<vk::Buffer> blocks;
    std::vector<vk::DescriptorSet> lights, shadowedLights;
    size_t bytes = 0;  // records and cube texels on the GPU
};

namespace features {

// The set's records, cubes (cubemap encoding), markers and per-slot grid blocks, uploaded once;
// their graph names imported. Throws std::invalid_argument for a set whose probes, grid and
// texels disagree, or that holds more faces than the device's image arrays.
std::unique_ptr<ReflectionResources> buildReflections(vk::VulkanContext& ctx, RendererGpu& g,
                                                     const ReflectionProbeSet& set);
// The set's grid with the frame's strength.
blocks::ReflectionBlock packReflections(const ReflectionResources& r, const RenderSettings& s);

}  // namespace features
}  // namespace terralux
