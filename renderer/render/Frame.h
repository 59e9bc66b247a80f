#pragma once
// What the renderer's features share while one frame is recorded (docs/ARCHITECTURE.md, "The
// frame"): the names of the frame graph's resources, the GPU state the renderer holds for its
// lifetime (RendererGpu), and the frame being recorded (Frame): its settings, which features take
// part, its targets. Each feature (render/features/) owns its resources and adds its passes from
// a Frame; TerrainRenderer::recordFrame decides who takes part and calls them in order. Private
// to the renderer: nothing outside renderer/render/ includes it.

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "render/FrameGraph.h"
#include "render/PipelineSet.h"
#include "render/RenderSettings.h"
#include "render/UniformBlocks.h"
#include "scene/DebugViews.h"
#include "scene/ShadowCascades.h"
#include "vk/Buffer.h"
#include "vk/Descriptors.h"
#include "vk/Image.h"
#include "vk/Pipeline.h"
#include "vk/PipelineLayout.h"
#include "vk/Readback.h"
#include "vk/RenderPass.h"
#include "vk/Sampler.h"
#include "vk/Swapchain.h"
#include "vk/VulkanContext.h"

namespace terralux {

class HeightfieldTracer;

namespace frame {

// Frame-graph resource names.
inline constexpr const char* kColor = "color";
inline constexpr const char* kDepth = "depth";
inline constexpr const char* kOutput = "output";  // the anti-aliased picture (features/Antialiasing.h)
inline constexpr const char* kReadback = "readback";
inline constexpr const char* kSwapchain = "swapchain";
inline constexpr const char* kVertices = "terrain-vertices";
inline constexpr const char* kIndices = "terrain-indices";
inline constexpr const char* kDetailVertices = "terrain-detail-vertices";  // the detail patches' (MeshLod.h)
inline constexpr const char* kDetailLight = "probe-detail-light";          // the probe light at them
inline constexpr const char* kMarkers = "markers";
inline constexpr const char* kLeaves = "leaves";
inline constexpr const char* kProbeCoefficients = "probe-coefficients";
inline constexpr const char* kProbeCells = "probe-cells";
inline constexpr const char* kProbeVolumes = "probe-volumes";
inline constexpr const char* kProbeErrorMaps = "probe-error-maps";
inline constexpr const char* kProbeLight = "probe-light";
inline constexpr const char* kShadowMaps = "shadow-maps";
inline constexpr const char* kSunVisibility = "sun-visibility";
inline constexpr const char* kWaterReflection = "water-reflection";
inline constexpr const char* kWaterReflectionDepth = "water-reflection-depth";
inline constexpr const char* kWaterScene = "water-scene";
inline constexpr const char* kWaterVertices = "water-vertices";
inline constexpr const char* kWaterIndices = "water-indices";
inline constexpr const char* kWaterField = "water-field";
inline constexpr const char* kReflectionGrid = "reflection-probe-grid";
inline constexpr const char* kReflectionRecords = "reflection-probe-records";
inline constexpr const char* kReflectionCubes = "reflection-probe-cubes";
inline constexpr const char* kReflectionMarkers = "reflection-probe-markers";
inline constexpr const char* kLpvLight = "lpv-light";
inline constexpr const char* kLpvGeometry = "lpv-geometry";
inline constexpr const char* kLpvWork = "lpv-work";
inline constexpr const char* kLpvScales = "lpv-scales";
inline constexpr const char* kSurfaceNormalAo = "surface-normal-ao";
inline constexpr const char* kSurfaceAlbedo = "surface-albedo";
inline constexpr const char* kSurfaceFilled = "surface-filled";
inline constexpr const char* kSkyImage = "sky-image";

// Pipeline variants of the terrain (all bits) and water (shadow, fog, reflection) passes.
inline constexpr int kProbeLightVariant = 1, kShadowVariant = 2, kFogVariant = 4, kReflectionVariant = 8,
                     kLpvVariant = 16, kLocalLightsVariant = 32;
// A pipeline's key for a pass of `samples` a pixel: render passes of other sample counts are not
// compatible, so a multisampled frame and the single-sampled water reflection each have their own.
inline int kSamplesKey(uint32_t samples) { return int(samples) << 8; }
// The lights set's variants, an index into the layouts: the shadow cascades, the reflection probes.
inline constexpr int kShadowedLights = 1, kReflectedLights = 2;
// The lights set a pipeline variant (or a frame with its shadows and reflections) binds.
inline constexpr int lightsOfVariant(int variant) {
    return ((variant & kShadowVariant) ? kShadowedLights : 0) | ((variant & kReflectionVariant) ? kReflectedLights : 0);
}

// The terrain mesh's vertices as the terrain and shadow pipelines read them: position and normal.
inline constexpr VkVertexInputBindingDescription kMeshBinding{0, 24, VK_VERTEX_INPUT_RATE_VERTEX};
inline constexpr VkVertexInputAttributeDescription kMeshPosition{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0};
inline constexpr VkVertexInputAttributeDescription kMeshNormal{1, 0, VK_FORMAT_R32G32B32_SFLOAT, 12};

inline constexpr VkShaderStageFlags kVertexFragment = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;

// Timestamps a slot's pool holds: one before the first pass and one after each.
inline constexpr uint32_t kFrameTimestamps = 64;

std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b);
void setViewport(VkCommandBuffer cb, uint32_t width, uint32_t height);
// Records the copy of a `width` x `height` colour image `source` (transfer-source layout) into
// `dest` (transfer-destination layout), resolving its samples when `resolve` (a multisampled source).
void copyColor(VkCommandBuffer cb, VkImage source, VkImage dest, uint32_t width, uint32_t height, bool resolve);
// One global memory dependency: what `srcStages` wrote through `srcAccess` is visible to
// `dstAccess` in `dstStages`.
void memoryBarrier(VkCommandBuffer cb, VkPipelineStageFlags srcStages, VkAccessFlags srcAccess,
                   VkPipelineStageFlags dstStages, VkAccessFlags dstAccess);

}  // namespace frame

// Each feature's resources (render/features/), present only while the scene uses the feature.
struct ProbeResources;
struct ShadowResources;
struct WaterResources;
struct ReflectionResources;
struct LpvResources;

// The frame slots: one per swapchain frame in flight, and one for a frame drawn offscreen without
// waiting (TerrainRenderer::beginOffscreen) while those are in flight.
inline constexpr uint32_t kOffscreenSlot = vk::kFramesInFlight;
inline constexpr uint32_t kRenderSlots = vk::kFramesInFlight + 1;

// What one frame in flight writes from the host: its uniform blocks and the sets that bind them.
// `shadowedLights` adds the cascades to `lights`; it exists while the shadow maps do (the lights
// sets with reflection probes belong to ReflectionResources).
// `reflectionCamera` and `reflectionView`: the view set again with the camera mirrored in the
// water (the planar reflection pass).
struct FrameSlot {
    vk::Buffer camera, surface, sunSky, atmosphere, shadow, overlay, reflectionCamera;
    // The terrain's horizon map (TLX_SUN_HORIZON_BINDING), host-visible, and the sweep it holds.
    vk::Buffer sunHorizon;
    uint64_t sunHorizonSerial = 0;
    vk::DescriptorSet view, lights, shadowedLights, overlays, reflectionView;
    // The terrain pass's LPV and local-lights set: its block, the lights (grown as needed), and
    // the set, written again when the bound volumes or the lights buffer change (`lpvSetKey`).
    vk::Buffer lpvBlock, localLights;
    size_t localLightCapacity = 0;
    vk::DescriptorSet lpvSet;
    uint64_t lpvSetKey = 0;
    // Timestamps around the frame graph's passes (devices that write them): the queries the last
    // frame drawn in this slot wrote, and its passes' names, read once its fence has passed.
    vk::UniqueQueryPool timestamps;
    vk::Buffer timestampResults;  // the frame's own copy of them, host-visible
    uint32_t timestampsWritten = 0;
    std::vector<std::string> timedPasses;
    double recordMilliseconds = 0.0;
    uint32_t width = 0, height = 0;  // the size the frame drawn in this slot was asked for
    // The gizmo lines of the frame drawn in this slot (RenderSettings::gizmos), grown as needed.
    vk::Buffer gizmos;
    size_t gizmoCapacity = 0;
};

// The frame's colour and depth, drawn at `scale` x the output's width and height (or with
// `samples` a pixel), and, when a pass anti-aliases the picture, the output image it writes and
// the set that reads the colour (or the output a resolve writes).
// The read-back holds the output's pixels.
struct RenderTarget {
    vk::Image color, depth;  // multisampled with samples > 1 (msaa), resolved into output
    vk::Framebuffer framebuffer;
    vk::Readback readback;
    uint32_t width = 0, height = 0, scale = 1, samples = 1;
    vk::Image output;
    vk::Framebuffer outputFramebuffer;
    vk::DescriptorSet source;
};

// The surface maps the view set binds (SurfaceMaps.h), always present: a terrain without AO or
// an albedo map binds neutral ones.
struct SurfaceTextures {
    vk::Image normalAo, albedo, filled;
    vk::Image sky;  // the sky's equirectangular radiance (a 1 x 1 placeholder without one)
};

// What the renderer holds on the GPU for its lifetime: the terrain mesh, the frame slots and
// targets, the render passes and layouts every feature shares, and each feature's resources.
// Pipelines are built on first use (lavapipe compiles a pipeline when it is created); the
// terrain's, the water's and the sky's may be built on a worker ahead of the frame (PipelineSet.h).
struct RendererGpu {
    vk::Buffer vertices, markers, leaves;
    // The detail patches' vertices (position and normal, as `vertices`), and which set of them
    // (TerrainRenderer's detail serial).
    vk::Buffer detailVertices;
    uint32_t detailVertexCount = 0;
    uint64_t detailSerial = 0;
    // The terrain's triangles at the level of detail drawn (host-visible, written once per choice
    // of levels, where it was made), and which choice that is: a new one retires the old, which
    // frames in flight may still read.
    vk::Buffer terrainIndices;
    uint64_t terrainIndicesSerial = 0;
    SurfaceTextures surface;
    vk::Sampler trilinear;
    vk::UniqueSetLayout viewLayout;
    std::unique_ptr<ProbeResources> probes;
    std::unique_ptr<ShadowResources> shadows;
    std::unique_ptr<WaterResources> water;
    vk::Sampler linear;
    vk::UniqueSetLayout waterLayout;
    std::array<vk::PipelineLayout, 4> waterLayouts;  // by lights variant
    // The sun-visibility view's per-vertex attribute (stride 32, like the probe light), and the
    // sun and surface it was traced for.
    vk::Buffer sunVisibility;
    glm::vec4 sunVisibilityKey{0.0f};
    int sunVisibilitySkirt = -1;
    std::unique_ptr<HeightfieldTracer> tracer;
    bool tracerSkirt = true;
    std::vector<FrameSlot> slots;
    std::unique_ptr<RenderTarget> target;
    // The targets of the sizes drawn lately (TargetSet.h): a metered frame's 128-pixel meter,
    // the dynamic-resolution steps and the full frame. Going back to one allocates nothing and
    // waits for nothing.
    std::vector<std::unique_ptr<RenderTarget>> spareTargets;
    size_t targetAllocations = 0;
    vk::RenderPass clearPass, drawPass, shadowPass;
    // The camera's clearing and drawing passes for a multisampled target, by its samples a pixel
    // (> 1); built with the first target of that count.
    std::map<uint32_t, std::pair<vk::RenderPass, vk::RenderPass>> multisampledPasses;
    const vk::RenderPass& clearPassFor(uint32_t samples) const;
    const vk::RenderPass& drawPassFor(uint32_t samples) const;
    vk::Sampler depthSampler;
    vk::UniqueSetLayout emptySet;
    std::array<vk::UniqueSetLayout, 4> lightsLayouts;     // by lights variant
    std::array<vk::PipelineLayout, 4> terrainLayouts;     // view and lights, by lights variant
    vk::PipelineLayout overlayLayout, probeLayout, shadowDepthLayout;
    std::unique_ptr<ReflectionResources> reflections;
    std::unique_ptr<LpvResources> lpv;
    uint64_t lpvGeneration = 1;  // counts setLpv calls: a slot's LPV set is written for one
    vk::Buffer lpvDummy;  // one vec4 standing in for the volumes where none are bound
    vk::UniqueSetLayout lpvLayout;
    std::array<vk::PipelineLayout, 4> terrainLpvLayouts;  // view, lights and the LPV set, by lights variant
    vk::PipelineLayout lpvSampleLayout, lpvPropagateLayout;
    vk::UniquePipeline lpvSample, lpvPropagate;
    // Timestamps around the last propagation pass (devices that write them).
    vk::UniqueQueryPool lpvQueries;
    bool lpvTimed = false;
    // Terrain pipelines by variant: kProbeLightVariant | kShadowVariant | kFogVariant |
    // kReflectionVariant | kLpvVariant | kLocalLightsVariant (either of the last two: the TLX_LPV
    // shaders and layout).
    // Keyed also by the samples a pixel of the pass they draw in (kSamplesKey). This set and the
    // two below may build on a worker (PipelineSet.h): declared after the passes and layouts
    // their builds read, they wait for them before those go.
    PipelineSet terrain;
    // The water surface's, by kShadowVariant | kFogVariant | kReflectionVariant and samples.
    PipelineSet waterPipelines;
    // The sky behind the terrain's, by fog and samples.
    PipelineSet sky;
    // The probe pass's compute pipeline (key 0), on probeLayout.
    PipelineSet probePass;
    std::map<int, vk::UniquePipeline> markerPipelines, leafPipelines, gizmoPipelines;
    vk::UniquePipeline shadowDepth;
    // The anti-aliasing pass: its colour-only render pass, layout and pipelines by
    // (ssaa ? 2 : 0) + (scene-linear output ? 1 : 0).
    vk::RenderPass outputPass;
    vk::UniqueSetLayout antialiasSetLayout;
    vk::PipelineLayout antialiasLayout;
    std::array<vk::UniquePipeline, 4> antialias;
    FrameGraph graph;
    ~RendererGpu();
};

// The frame being recorded: what every feature's passes read. Lives until the frame graph has
// executed, so passes may refer to it.
struct Frame {
    vk::VulkanContext& ctx;
    RendererGpu& g;
    FrameSlot& slot;
    uint32_t slotIndex = 0;
    const RenderSettings& s;
    DebugView view;

    // Who takes part: a null feature adds no pass and binds nothing.
    ProbeResources* probes = nullptr;            // volumes bound, probes on, the view reads them
    ReflectionResources* reflections = nullptr;  // a set bound, probes on, the view reads specular
    LpvResources* lpvVolumes = nullptr;          // volumes bound, lit by them or shown
    ShadowResources* shadows = nullptr;          // shadows on, the sun up (and lit), the view draws them
    WaterResources* water = nullptr;             // water on and the view draws it
    bool localLights = false;     // the scene has point or spot lights and the view lights with them
    bool lpvSet = false;          // lpvVolumes or localLights: the terrain binds its LPV set
    bool fog = false;
    bool sky = false;             // the view draws the sky behind the terrain
    bool sunVisibility = false;   // the per-vertex attribute holds the traced sun visibility
    bool waterShading = false;    // the view shades the water (reflection, refraction)
    bool planarReflection = false;
    bool drawMarkers = false, drawReflectionMarkers = false, drawLeaves = false, drawGizmos = false;

    // The terrain mesh and the overlays' instances.
    uint32_t vertexCount = 0, indexCount = 0, markerCount = 0, leafCount = 0, gizmoCount = 0;
    uint32_t skirtIndexCount = 0;  // drawn after indexCount by the shadow pass alone (terrain.skirt)
    // The detail patches' triangles, from detailFirstIndex in indexBuffer, over g.detailVertices,
    // then their skirt's (the shadow pass alone, as skirtIndexCount).
    uint32_t detailIndexCount = 0, detailFirstIndex = 0, detailSkirtIndexCount = 0;
    VkBuffer indexBuffer = VK_NULL_HANDLE;  // the level of detail's triangles, then its skirt's
    uint64_t lodSerial = 0;                 // which levels those are (TerrainRenderer::updateLod)
    // The cascades' depth range this frame (with shadows), and the light projections of the
    // cascades whose maps it reads (empty without shadows): those before the horizon map's
    // first, or all where the water reads them.
    CascadeRange cascadeRange;
    int horizonFrom = 0;  // the first cascade the horizon map stands in for (the count: none)
    std::vector<glm::mat4> lightMatrices;

    // The target.
    uint32_t width = 0, height = 0;
    uint32_t samples = 1;  // a pixel, of the colour and depth targets (msaa)
    VkFramebuffer framebuffer = VK_NULL_HANDLE;
    glm::vec3 background{0.0f};  // the clear colour where no pass draws the sky

    int lightsVariant() const;
    // The lights set the lit passes bind: with the cascades and the reflection probes as taking part.
    const vk::DescriptorSet& lights() const;
    // Begins the pass that draws on top of what the frame holds (sky, water, overlays).
    void beginDrawing(VkCommandBuffer cb) const;
    // Begins the clearing render pass on a framebuffer of `fbSamples` a pixel, with the viewport over it.
    void beginClearing(VkCommandBuffer cb, VkFramebuffer fb, uint32_t fw, uint32_t fh, glm::vec3 clearColor,
                       uint32_t fbSamples = 1) const;
};

}  // namespace terralux
