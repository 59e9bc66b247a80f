#pragma once
// The water plane: its field and mesh, its block, and its passes (the planar reflection, the copy
// of the frame under it, the water surface).

#include <memory>
#include <vector>

#include <glm/vec2.hpp>

#include "render/Frame.h"
#include "render/PipelineSet.h"
#include "terrain/Heightfield.h"

namespace terralux {

// Present only while the scene has water. The field and mesh follow the level; the reflection
// target and the copy of the frame follow the frame's size.
// What a frame size needs of the water: the planar reflection at the reflection scale, the copy
// of the frame under the water, and the per-slot sets that bind them with the block and the field.
struct WaterTargets {
    uint32_t width = 0, height = 0, reflectionWidth = 0, reflectionHeight = 0;
    vk::Image reflection, reflectionDepth, scene;
    vk::Framebuffer reflectionFramebuffer;
    std::vector<vk::DescriptorSet> sets;  // per frame slot: block, reflection, scene, field
};

struct WaterResources {
    float level = 0.0f, margin = 0.0f;
    glm::ivec2 fieldSize{1, 1};
    vk::Image field;  // RG16F: depth below the level (negative on land), distance to shore
    vk::Buffer vertices, indices;
    uint32_t indexCount = 0;
    float spacing = 1.0f;  // metres between mesh vertices
    std::vector<vk::Buffer> blocks;  // per frame slot: the WaterBlock
    // The frame size's targets, and those of the sizes drawn lately, kept as the frame's own
    // are (RendererGpu::spareTargets).
    std::unique_ptr<WaterTargets> targets;
    std::vector<std::unique_ptr<WaterTargets>> spareTargets;
};

namespace features {

// The water's field and mesh as setWater built them.
struct WaterInputs {
    float level = 0.0f;           // engine y
    float shoreFadeDistance = 0;  // metres (water::shoreFadeDistance)
    glm::vec2 fieldSize{1.0f};    // texels of the depth/shore field
    float meshSpacing = 1.0f;     // metres between the water mesh's vertices
};
blocks::WaterBlock packWater(const RenderSettings& s, const WaterInputs& in);
// The field over the footprint (depth below `level` and distance to shore) and the mesh over
// every cell whose bed lies below level + `margin`, with a block per frame slot.
std::unique_ptr<WaterResources> buildWater(vk::VulkanContext& ctx, const Heightfield& hf, float level, float margin);
// Whether `t` serves a frame of `width` × `height` with the reflection at `reflectionScale`.
bool waterTargetsServe(const WaterTargets* t, uint32_t width, uint32_t height, float reflectionScale);
// The targets of such a frame, with the per-slot sets that bind them with w's blocks and field.
std::unique_ptr<WaterTargets> buildWaterTargets(vk::VulkanContext& ctx, const RendererGpu& g, const WaterResources& w,
                                                uint32_t width, uint32_t height, float reflectionScale);
// The water set: its block, the reflection, the frame under the water and the field (read by the
// mesh too). Null views: the layout alone.
vk::DescriptorSetBuilder waterSetBuilder(const vk::Buffer& block, VkImageView reflection, VkImageView scene,
                                         VkImageView field, VkSampler sampler);
// The water surface's pipeline variant (Frame.h's bits: shadows, fog, reflection probes), and
// its build for a pass of `samples` a pixel, which may run on a worker (PipelineSet).
int waterVariant(bool shadows, bool fog, bool reflections);
PipelineSet::Build waterPipelineBuild(const vk::VulkanContext& ctx, const RendererGpu& g, int variant,
                                      uint32_t samples);
// The planar reflection (terrain and sky from the mirrored camera), the copy of the frame the
// water refracts, and the water surface; each only where the frame needs it.
void addWaterPasses(Frame& f);

}  // namespace features
}  // namespace terralux
