#pragma once
// The terrain feature: the camera and surface blocks (the view set every pass binds) and the
// terrain pass, lit by whatever features take part (probe light, shadows, fog, reflection
// probes, the LPV and local lights), drawn into the frame and, mirrored, into the water's planar
// reflection.

#include <functional>
#include <optional>
#include <vector>

#include <glm/vec2.hpp>

#include "render/Frame.h"
#include "render/PipelineSet.h"

namespace terralux::features {

// The terrain's extent and maps as the surface block needs them.
struct SurfaceInputs {
    glm::vec2 footprintMin{0.0f}, footprintSpan{0.0f};  // (x, z) of the DEM's footprint, metres
    glm::vec2 normalAoMapSize{1.0f}, albedoMapSize{1.0f};  // texels, level 0
    bool albedoMap = false;  // the albedo map holds the albedo (else s.albedo)
    bool ao = false;         // the normal-AO map holds the horizon AO
    float probeAoLevel = 0.0f;  // the normal-AO mip level as coarse as the finest probes (0: none)
    // The skirt beyond the footprint as the sky pass draws it: the border's mean height and, with
    // an albedo map, its mean linear albedo (else s.albedo).
    float borderHeight = 0.0f;
    bool skyImage = false;    // a sky image is bound (TerrainRenderer::setSkyImage)
    float skyImageLod = 0.0f; // its mip level a pixel spans
    std::optional<glm::vec3> borderAlbedo;
};

// Camera and frame: the view-projection for `extent` (the terrain's largest span, which sets the
// clip planes), the viewport, the view and what the per-vertex attribute holds.
blocks::CameraBlock packCamera(const RenderSettings& s, float extent, const DebugView& view);
// The camera mirrored in the water plane at `level`, drawing scene-linear beauty into a
// `width` × `height` reflection.
blocks::CameraBlock packMirroredCamera(const RenderSettings& s, const blocks::CameraBlock& camera, float extent,
                                       float level, float width, float height);
// Terrain surface and material: albedo, GGX roughness, exposure, AO use, micro-detail.
blocks::SurfaceBlock packSurface(const RenderSettings& s, const SurfaceInputs& in);

// The terrain pipeline's variant (Frame.h's bits) for a frame with these parts: the per-vertex
// attribute (probe light or sun visibility), shadows, fog, reflection probes, LPV volumes, local lights.
int terrainVariant(bool vertexAttribute, bool shadows, bool fog, bool reflections, bool lpvVolumes, bool localLights);
// Builds the terrain pipeline of `variant` for a pass of `samples` a pixel; reads only handles
// that outlive it, so it may run on a worker (PipelineSet).
PipelineSet::Build terrainPipelineBuild(const vk::VulkanContext& ctx, const RendererGpu& g, int variant,
                                        uint32_t samples);
// Records the terrain mesh with the frame's pipeline variant, with `viewSet` (the frame's view or
// the mirrored camera's), in a pass of `samples` a pixel (the frame's, or the reflection's 1).
using TerrainDraw = std::function<void(VkCommandBuffer, VkDescriptorSet viewSet)>;
TerrainDraw terrainDraw(Frame& f, uint32_t samples);
// The terrain pass's uses and bindings beyond `targets`, for a pass named `name` with `viewSet`.
PassInfo terrainPassInfo(const Frame& f, const char* name, std::vector<ResourceUse> targets,
                         const vk::DescriptorSet& viewSet);
// The pass that clears the frame and draws the terrain.
void addTerrainPass(Frame& f);

}  // namespace terralux::features
