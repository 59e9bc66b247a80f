#pragma once
// Diffuse probe volumes: the baked grids on the GPU and the compute pass that evaluates them at
// every terrain vertex (the probe light the terrain pass reads as a vertex attribute).

#include <memory>
#include <vector>

#include "render/Frame.h"
#include "render/TerrainRenderer.h"

namespace terralux {

// Present only while volumes are bound.
struct ProbeResources {
    vk::Buffer block, coeffs, cells, volumes, errors, light;
    vk::DescriptorSet set;
    bool lightStale = true;  // the probe pass has not run since the volumes changed
    // The same light at the detail patches' vertices (RendererGpu::detailVertices), for the set of
    // them `serial` names.
    struct Detail {
        vk::Buffer block, light;
        vk::DescriptorSet set;
        uint64_t serial = 0;
        uint32_t vertexCount = 0;
        bool stale = true;
    };
    std::unique_ptr<Detail> detail;
    int volumeCount = 0;
    bool anyErrorMap = false;  // some volume carries an interpolation-error map
    size_t bytes = 0;          // coefficients and cells on the GPU
};

namespace features {

// The volumes' records, coefficients (with the moved flag), cells and error maps uploaded, the
// per-vertex light buffer for `vertexCount` vertices, the probe pass's set; their graph names
// imported.
std::unique_ptr<ProbeResources> buildProbes(vk::VulkanContext& ctx, RendererGpu& g, uint32_t vertexCount,
                                            const std::vector<GpuProbeVolume>& volumes);
// The probe light's buffer and set for the detail patches' vertices g.detailVertices holds now.
std::unique_ptr<ProbeResources::Detail> buildDetailLight(vk::VulkanContext& ctx, RendererGpu& g, const ProbeResources& p);
// The probe pass's compute pipeline, on the layout of `p`'s set (made here, on the calling thread,
// the first time): built on a worker for a viewport frame (TerrainRenderer::pipelinesReady;
// lavapipe compiles it in 40-50 ms), else where the frame records.
PipelineSet::Build probePassBuild(const vk::VulkanContext& ctx, RendererGpu& g, const ProbeResources& p);
// Evaluates the volumes at the vertices, once after they changed, and at the detail patches'
// vertices, once after either changed.
void addProbePass(Frame& f);

}  // namespace features
}  // namespace terralux
