#pragma once
// Draws the terrain offscreen the way the engine will light it, or one of the debug views. A frame
// is an ordered list of passes (FrameGraph): the probe pass (compute, only after the probes
// changed), the sun's shadow cascades (only when the view draws shadows and they moved), the
// terrain, the sky behind it, the overlays (probe markers, octree leaves), then either the readback
// (`terralux --render`, the tests, a viewport grab) or the blit to a window's swapchain. A
// subsystem the frame does not use adds no pass and no binding.

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "bake/ProbeDiagnostics.h"
#include "bake/Sky.h"
#include "bake/SphericalHarmonics.h"
#include "render/FrameGraph.h"
#include "render/RenderSettings.h"
#include "scene/DebugViews.h"
#include "scene/OrbitCamera.h"
#include "scene/ShadowCascades.h"
#include "scene/SceneDescription.h"
#include "terrain/Heightfield.h"
#include "terrain/MeshLod.h"
#include "vk/Buffer.h"
#include "vk/Image.h"
#include "vk/Swapchain.h"
#include "water/Water.h"
#include "vk/VulkanContext.h"

namespace terralux {

struct RendererGpu;  // render/Frame.h
struct RenderTarget;  // render/Frame.h
struct Frame;
struct WaterResources;  // render/features/Water.h
struct ReflectionProbeSet;  // bake/ReflectionBake.h
namespace features {
struct AntialiasingPlan;  // render/features/Antialiasing.h
}  // namespace features
namespace lpv {
class Volumes;  // lpv/Lpv.h
struct Sample;
}  // namespace lpv

// One baked volume as the GPU reads it: the .shprobe grid (occupancy + coefficients).
struct GpuProbeVolume {
    std::string name;  // the volume's, for overlays and messages
    glm::uvec3 dims{1};
    glm::vec3 origin{0.0f};
    float spacing = 1.0f;
    std::vector<std::array<glm::vec3, 9>> coeffs;  // per probe
    std::vector<int32_t> occupancy;                // dims.x * dims.y * dims.z
    float fallbackBlendDistance = 0.0f;
    bool irradianceEncoded = false;                // coefficients hold Â_l L_k
    float scale = 1.0f;                            // the file's default SH scale
    // What the bake wrote beside the file (moved probes and the error map of the diagnostics views);
    // unset for bakes without it.
    std::optional<ProbeDiagnostics> diagnostics;
};

struct RenderedImage {
    uint32_t width = 0, height = 0;
    std::vector<float> rgba;      // row 0 at the top
    std::vector<uint8_t> bytes;   // instead, with RenderSettings::readbackBytes: unitToByte of each
    double milliseconds = 0.0;    // draw + readback, wall clock
};

// What one frame cost (TerrainRenderer::lastFrameTimings): the GPU time of each pass of the frame
// graph, from timestamps, and the host's part.
struct FrameTimings {
    struct Pass {
        std::string name;
        double gpuMilliseconds = 0.0;  // between the timestamps before and after it, barriers included
    };
    std::vector<Pass> passes;          // in order; empty where the device writes no timestamps
    double gpuMilliseconds = 0.0;      // first timestamp to last: the passes summed
    double recordMilliseconds = 0.0;   // host: recording the frame (uniforms, passes, barriers)
    double readbackMilliseconds = 0.0; // host: converting the read-back pixels (render() only)
    uint32_t width = 0, height = 0;    // the pixels asked for (the viewport's dynamic resolution)
    bool gpuTimed() const { return !passes.empty(); }
};

class TerrainRenderer {
public:
    // Large DEMs are drawn from every k-th row and column (always including the last), the
    // smallest k that keeps the mesh within `vertexBudget`: a uniform grid, so no cracks.
    // (Where it is, the level of detail draws the patches near the camera from the DEM's own
    // vertices: kDetailVertexBudget.)
    static constexpr size_t kMeshVertexBudget = size_t(1) << 22;
    TerrainRenderer(vk::VulkanContext& ctx, const Heightfield& hf, size_t vertexBudget = kMeshVertexBudget);
    ~TerrainRenderer();

    // Binds the volumes (none: the probe subsystem and its buffers go away); the next frame that
    // needs probe light runs the probe pass.
    void setProbeVolumes(const std::vector<GpuProbeVolume>& volumes);
    // Binds a reflection-probe set (null: none; the subsystem and all its GPU resources go away).
    // Its probes are uploaded here, once; frames whose view reads the environment's specular
    // bind them with the lights. Throws std::invalid_argument for a set whose probes, grid and
    // texels disagree, or that holds more faces than the device's image arrays, and
    // std::runtime_error for a cubemap set on a device without cube-map arrays.
    void setReflectionProbes(std::shared_ptr<const ReflectionProbeSet> set);
    // Whether the reflection subsystem holds GPU resources (a set is bound).
    bool hasReflectionResources() const;
    // Binds light propagation volumes (null: none; their GPU buffers go away). Their cascades,
    // quality, cone samples and intensity are the volumes' own settings. Volumes made with
    // lpv::Propagation::Renderer are propagated here, by a compute pass (shaders/
    // lpv_propagate.comp) that the first frame reading them runs ("lpv-propagate").
    void setLpv(std::shared_ptr<const lpv::Volumes> volumes);
    // Whether volumes for this renderer are best propagated by it: on a GPU, yes; on a CPU device
    // (lavapipe) the CPU's own propagation is 2-4x faster than the pass on the same cores
    // (bench_render BM_LpvUpdate) and runs on the update's worker rather than in a frame.
    bool propagatesLpv() const;
    const std::shared_ptr<const lpv::Volumes>& lpv() const;
    bool hasLpvResources() const;
    // Volumes::evaluate and Volumes::ambientOcclusion of the bound LPV on the GPU, by the terrain
    // shader's own code, at each query (position, unit normal, unit direction toward the eye),
    // over cascades `lastCascade` down to 0 (-1: all), at the volumes' quality; waits for the GPU.
    // Empty without an LPV.
    struct LpvSample {
        glm::vec3 irradiance{0.0f}, specular{0.0f};  // lpv::Sample's
        float ao = 1.0f;
    };
    std::vector<LpvSample> sampleLpv(const std::vector<std::array<glm::vec3, 3>>& queries, int lastCascade = -1);
    // The bound LPV's light as the terrain reads it (Lpv.h's layout, cascades one after another),
    // propagated first if that is still owed: Volumes' `accumulated` for volumes it propagated.
    // Waits for the GPU. Empty without an LPV.
    std::vector<float> readLpvLight();
    // The GPU time of the last propagation pass, milliseconds, from timestamps; none before the
    // first, or where the device writes no timestamps. Waits for the GPU.
    std::optional<double> lpvPropagationMilliseconds();
    // The LPV views' white point (lpv::lightRange of cascade 0, W/(m²·sr)): views 61 and 64 show
    // E/π divided by it through the display curve. None without an LPV holding light.
    std::optional<double> lpvViewRange() const;
    // Bytes of the bound reflection probes on the GPU: their records and cube texels.
    size_t reflectionBytes() const { return reflectionBytes_; }
    // Probe positions for the overlay: xyz, w = 1 valid, 2 moved up, 0 inside the terrain.
    void setProbePositions(const std::vector<glm::vec4>& positions);
    // Octree leaves for the leaf overlay: min corner xyz, w edge (metres).
    void setProbeLeaves(const std::vector<glm::vec4>& leaves);
    // The sky visibility per DEM vertex (horizonSkyVisibility's layout), or empty for none: the
    // surface maps are built and uploaded again.
    void setAmbientOcclusion(const std::vector<float>& perVertex);
    // The same in two steps: the maps built and uploaded where prepareSurfaceMaps is called (the
    // UI's AO worker, holding vk::WorkerCommands: over N42E001 this took the UI thread 100-500 ms
    // on lavapipe), then swapped in, the old ones retired rather than waited for.
    struct SurfaceMapTextures {
        vk::Image normalAo, filled;
        glm::ivec2 size{1, 1};
        uint64_t terrain = 0;  // the serial of the heightfield they were made for
        bool ao = false;
    };
    static SurfaceMapTextures prepareSurfaceMaps(const vk::VulkanContext& ctx, const Heightfield& hf,
                                                 const std::vector<float>& ao);
    void setSurfaceMaps(SurfaceMapTextures maps);
    // An albedo map over the footprint (texel centres corner to corner, row 0 north, 8-bit sRGB,
    // 3 bytes a texel: SurfaceAlbedo::srgb), or width 0 for the constant albedo of RenderSettings.
    void setAlbedoMap(int width, int height, const std::vector<uint8_t>& srgb);
    // The sky the picture views draw behind the terrain at full resolution: an equirectangular
    // radiance image, row 0 at the zenith (renderer/bake/Sky.h's mapping), drawn × the settings'
    // skyImageScale turned by skyImageRotation. Empty: the sky's SH (a uniform sky).
    void setSkyImage(int width, int height, const std::vector<glm::vec3>& radiance);
    bool hasAmbientOcclusion() const { return hasAo_; }
    // The water plane at `level` (engine y): the field of depth below the level and distance to
    // shore, and the mesh over every cell whose bed lies below level + `margin` (the highest a
    // crest reaches), are built for it. nullopt removes the water subsystem.
    void setWater(std::optional<float> level, float margin);
    bool hasWaterResources() const;
    // Texels a side of the water field (0 without water).
    glm::ivec2 waterFieldSize() const;
    // Texels a side of the normal-AO map's level 0.
    glm::ivec2 surfaceMapSize() const { return surfaceMapSize_; }
    // Draws a frame and reads it back, waiting for the GPU.
    RenderedImage render(const RenderSettings& settings);
    // Draws a frame and its read-back like render(), but submits it without waiting for the GPU
    // (in a slot of its own, so the swapchain's frames in flight go on): takeOffscreen() gives
    // the image once the GPU has drawn it. False, drawing nothing, while one is still untaken.
    bool beginOffscreen(const RenderSettings& settings);
    bool offscreenPending() const { return offscreen_.has_value(); }
    // Whether the device has finished it (takeOffscreen() then gives it).
    bool offscreenFinished() const { return offscreen_ && (offscreen_->read || offscreen_->submission.done()); }
    // The image beginOffscreen() drew, once the GPU has finished it (never waits); nullopt before
    // then and when none was begun.
    std::optional<RenderedImage> takeOffscreen();
    // Draws a frame into the swapchain's next image (a blit of the offscreen colour target, no
    // readback) and submits it without waiting for the GPU; the swapchain presents it once it
    // has finished (vk::Swapchain::presentIfDone). False when nothing could be shown.
    bool present(const RenderSettings& settings, vk::Swapchain& swapchain);
    // Whether a frame of `settings` finds the terrain's, the sky's and the water's pipelines for it
    // built (a CPU device compiles the terrain's in 120-170 ms, the sky's in 10-16 ms); those
    // missing start building on a worker. A viewport that must not wait draws such a frame once
    // this holds (ProjectRenderer::waitingToDraw polls pipelinesBuilding()); any other frame
    // builds what it lacks where it is recorded. The shadow-depth, overlay and anti-aliasing
    // pipelines (0.5-6 ms each on lavapipe) are still built where the frame is recorded.
    bool pipelinesReady(const RenderSettings& settings);
    bool pipelinesBuilding() const;
    // No work of this renderer's is still running on a worker (pipeline builds, a horizon sweep,
    // a choice of levels): destroying it then waits for none.
    bool workersFinished() const;
    // Pipelines of those kinds built where a frame was recorded, and on workers.
    size_t pipelinesBuiltInline() const;
    size_t pipelinesBuiltOnWorkers() const;
    // The passes of the last frame, in order, with what each used and bound.
    const std::vector<PassInfo>& lastFramePasses() const;
    // The cost of the last frame whose GPU work is known to have finished: after render(), that
    // frame; after present(), the frame last drawn in the slot it reused (whose fence it waited
    // for), so reading them never stalls a later frame.
    const FrameTimings& lastFrameTimings() const { return timings_; }
    // The anti-aliasing the last frame was drawn with: its settings', or for an msaa count the
    // device lacks the largest it has below (fxaa with none); off for a data view.
    Antialiasing drawnAntialiasing() const { return drawnAntialiasing_; }
    // Whether the probe subsystem holds GPU resources (volumes are bound).
    bool hasProbeResources() const;
    // Whether the shadow subsystem holds GPU resources (a frame drew shadows and the scene's
    // shadows are still on).
    bool hasShadowResources() const;
    // The next frame that draws shadows draws its maps again, as every frame of a moving camera
    // does (a still camera keeps the maps it drew): what a measurement of their cost times.
    void redrawShadowMaps();
    // The cascades of the last frame that drew shadows (empty when none).
    const std::vector<Cascade>& lastCascades() const { return cascades_; }
    // How often the sun's visibility was traced at the vertices (cached per sun and surface).
    size_t sunVisibilityTraces() const { return sunTraces_; }
    // How often the terrain's horizon toward the sun was swept for the shadows (shadows.heightfield;
    // once per sun and surface), and the map of the last sweep: the sun's visible share at each of
    // its vertices, row-major (horizonMapInfo's width × height).
    size_t sunHorizonSweeps() const { return sunHorizonSweeps_; }
    // A frame that does not wait for the sweep (RenderSettings::waitForHorizon off) starts it on a
    // worker and draws the map held: whether one is under way, and whether it has finished (the
    // next frame takes its map).
    bool sunHorizonSweeping() const { return pendingHorizon_ != nullptr; }
    bool sunHorizonSwept() const;
    // Whether a frame of `settings` finds the horizon map it reads: a renderer's first is swept
    // on a worker (N42E001's takes 90 ms on the 2-core machine), and a viewport that must not
    // wait draws that frame once it has landed (ProjectRenderer::waitingToDraw polls
    // sunHorizonAwaited()), as for pipelines. Later maps are swept while the frames draw the
    // one held.
    bool sunHorizonReady(const RenderSettings& settings);
    bool sunHorizonAwaited() const;
    const std::vector<float>& sunHorizonMap() const { return sunHorizonMap_; }
    HorizonMapInfo horizonMapInfo() const { return horizonMap_; }
    // The device memory the map takes: a byte a vertex in each frame slot.
    uint64_t horizonMapBytes() const;

    // How often a frame needed targets of a size neither the current nor the spare target had
    // (RendererGpu::spareTarget): a metered frame's meter and the frame itself allocate once.
    size_t targetAllocations() const;
    int meshStride() const { return stride_; }
    // The mesh's level of detail (terrain/MeshLod.h): square patches of the drawn grid, each
    // drawing every 2^l-th of its vertices, l chosen per frame so that the levels leave out at most
    // setLodPixelError pixels (1 by default; at 0 only what is exact) of the drawn grid as the
    // frame's camera sees it, in the picture views (the data views draw every vertex: they are
    // read against the bake vertex by vertex). The shadow maps and the water's reflection draw
    // the frame's levels.
    static constexpr uint32_t kLodPatchCells = 32;
    const lod::Patches& lodPatches() const { return patches_; }
    // What the drawn grid itself leaves out of the source DEM (metres, the largest of the
    // patches'; 0 when drawn whole). The levels keep what they leave out of the drawn grid
    // within the pixel; the screen error reported adds this.
    double decimationError() const {
        return decimation_.empty() ? 0.0 : *std::max_element(decimation_.begin(), decimation_.end());
    }
    void setLodPixelError(double pixels) { lodPixelError_ = pixels; }
    // Source resolution: where the drawn grid is decimated (meshStride() > 1), a picture frame draws
    // each patch whose drawn vertices leave more than the pixel out of the DEM from the DEM's own
    // vertices instead (MeshLod.h, detail patches), at the coarsest detail level within the
    // pixel, while their vertices fit the detail budget (kDetailVertexBudget unless set). Past
    // the budget, the largest error on screen is made as small as the budget allows: the patch
    // furthest off on screen moves to its cheapest finer state that is nearer (lod::allocateDetail),
    // while such a move fits.
    // Their vertices live in a buffer of their own, built when the set of such patches changes;
    // the probe pass lights them as it lights the drawn grid's.
    // setSourceDetail(false) draws the drawn grid alone (the benchmarks and tests compare).
    // The budget is for a frame of up to kDetailBudgetPixels (1280 x 720); a larger frame gets
    // it in proportion to its pixels, up to kDetailBudgetMaxScale times: a pixel's error needs
    // about as many vertices wherever it is, so a 1920 x 1080 frame keeps the pixel where a
    // 1280 x 720 one does (detailBudgetFor).
    static constexpr size_t kDetailVertexBudget = size_t(1) << 22;
    static constexpr double kDetailBudgetPixels = 1280.0 * 720.0;
    static constexpr double kDetailBudgetMaxScale = 4.0;
    static size_t detailBudgetFor(size_t budget, double rows, double aspect);
    void setSourceDetail(bool on) { sourceDetail_ = on; }
    void setDetailVertexBudget(size_t vertices) { detailVertexBudget_ = vertices; }
    // Detail levels a patch has (steps 2^d below the stride; 0 where the DEM is drawn whole).
    uint8_t detailLevels() const { return detailLevels_; }
    struct LodChoice {
        std::vector<uint8_t> levels;     // per patch
        std::vector<int8_t> detail;      // per patch: its detail level, or -1 where drawn from the drawn grid
        size_t detailVertices = 0;       // the detail buffer's vertices
        size_t triangles = 0;            // the terrain's, skirt aside
        double screenErrorPixels = 0.0;  // the largest of a patch's drawn surface against the DEM, as the
                                         // camera sees it at the patch's nearest point
    };
    // The levels the last frame drew.
    const LodChoice& lastLod() const { return drawnLod_.choice; }
    // Counts the triangle lists the frames have drawn (each new choice of levels is one).
    uint64_t levelOfDetailSerial() const { return drawnLod_.serial; }
    // A frame that does not wait for its levels (RenderSettings::waitForLevelOfDetail off) chooses
    // and builds them on a worker and draws the set held: whether one is under way, and whether it
    // has finished (the next frame draws it).
    bool levelOfDetailBuilding() const { return pendingLod_.valid(); }
    bool levelOfDetailBuilt() const;
    // Whether a frame of `settings` finds levels to draw: a viewport picture (waitForLevelOfDetail
    // off) of a renderer that holds none has its first set chosen on a worker (a 16 384² DEM's
    // takes 120-140 ms on the 2-core machine), and a viewport that must not wait draws that frame
    // once it has landed (ProjectRenderer::waitingToDraw polls levelOfDetailAwaited()), as for
    // the first horizon map. Any other frame is ready: it chooses its own where it records.
    bool levelOfDetailReady(const RenderSettings& settings);
    bool levelOfDetailAwaited() const;
    size_t vertexCount() const { return vertexCount_; }
    size_t triangleCount() const { return indexCount_ / 3; }
    size_t probeBytes() const { return probeBytes_; }

private:
    struct Output;
    // Who takes part in a frame, from its settings, its view and what is bound (recordFrame and
    // pipelinesReady decide alike).
    struct Parts {
        bool probes = false, reflections = false, lpvVolumes = false, localLights = false;
        bool sunVisibility = false, sky = false, shadowed = false, water = false, waterShading = false;
        bool planarReflection = false;
    };
    Parts partsOf(const RenderSettings& s, const DebugView& view) const;
    void ensureMultisampledPasses(uint32_t samples);
    void recordFrame(VkCommandBuffer cb, uint32_t slot, const RenderSettings& s, const Output& out);
    void writeBlocks(Frame& f);
    void ensureTarget(uint32_t width, uint32_t height, const features::AntialiasingPlan& plan);
    features::AntialiasingPlan antialiasingOf(const RenderSettings& s) const;
    static const RenderSettings& drawnSettings(const RenderSettings& s, const features::AntialiasingPlan& plan,
                                               RenderSettings& scaled);
    void ensureShadowMaps(int resolution, int cascades);
    void updateSunVisibility(const SunLight& sun, bool skirt);
    void updateSunHorizon(const SunLight& sun, bool skirt, bool wait);
    // A sweep's map at the horizon map's vertices and packed a byte a vertex, made where it is
    // swept (a 16 384² DEM's took the UI thread 190 ms to resample and pack).
    struct SweptHorizon {
        std::vector<float> map;
        std::vector<uint32_t> bytes;
    };
    std::function<SweptHorizon()> sunHorizonSweep(const SunLight& sun, bool skirt) const;
    SweptHorizon sweptHorizonOf(std::vector<float> perVertex) const;
    void startSunHorizonSweep(const SunLight& sun, bool skirt);  // on a worker (pendingHorizon_)
    void installSunHorizon(SweptHorizon swept, const glm::vec4& key, bool skirt);
    void dropSweptHorizon();
    void uploadSurfaceMaps(const std::vector<float>& ao);
    void buildViewSets();
    void ensureWaterTargets(uint32_t width, uint32_t height, float reflectionScale);
    void buildReflectionSets();
    void propagateLpvNow();  // runs the owed propagation in a submission of its own
    void readFrameTimings(uint32_t slot);  // the slot's last frame into timings_; its fence has passed
    // Resources replaced while a frame in flight may still read them: kept until every frame slot
    // has been waited for since (kFramesInFlight frames begun), or the queue has been waited
    // for, then released. Replacing them never waits for the device.
    template <class T>
    void retire(T&& resource) {
        retired_.push_back({framesBegun_ + vk::kFramesInFlight, std::make_shared<std::decay_t<T>>(std::move(resource))});
    }
    void releaseRetired(bool idle);
    // The frame beginOffscreen() submitted, and its pixels once read: they are read as soon as
    // the GPU has finished, and before anything may write its read-back again or free its target.
    struct Offscreen {
        vk::Submission submission;
        RenderTarget* target = nullptr;
        RenderedImage image;
        bool read = false;
        std::chrono::steady_clock::time_point start;
    };
    std::optional<Offscreen> offscreen_;
    // Reads the offscreen frame's pixels if the GPU has finished it (always so after a wait for
    // the queue, which is when anything may next write its read-back or free its target).
    void readOffscreen();
    struct Retired {
        uint64_t releaseAt;  // framesBegun_ at which no frame can still read it
        std::shared_ptr<void> resource;
    };
    std::vector<Retired> retired_;
    // Textures whose levels the next recorded frame copies in (replaceTexture).
    std::vector<vk::StagedTexture> pendingTextures_;
    void replaceTexture(vk::Image& held, vk::StagedTexture staged);
    uint64_t framesBegun_ = 0;  // swapchain frames begun: each waited for its slot's frame before
    // Chooses the frame's levels for `rows` of output; builds their triangles when they changed
    // (++lodSerial_).
    // `sourceDetail`: the frame may draw detail patches (its per-vertex attribute, if any, is the
    // probe light, which the probe pass evaluates at their vertices too).
    // Runs on a worker for a frame that does not wait (RenderSettings::waitForLevelOfDetail): it
    // reads the immutable mesh and DEM, its own caches and `inputs`, and writes only the working
    // state below, which publishLod hands to the frames.
    struct LodInputs;
    void updateLod(const RenderSettings& s, double rows, bool picture, bool sourceDetail, bool shadowed,
                   const LodInputs& inputs);
    lod::Patches patches_;
    lod::SkirtVertices skirt_;
    std::vector<double> decimation_;  // per patch
    lod::SurfaceErrorCache lodSurfaceCache_;  // what each patch's drawn surface leaves out, by its levels
    double lodPixelError_ = 1.0;
    bool sourceDetail_ = true;
    bool lodPicture_ = false;  // the last levels were chosen for a picture frame (not every vertex)
    // What the levels are chosen by besides the camera, the sun and the frame's rows: a frame
    // that keeps the shadow maps' levels keeps them only while these stand.
    struct LodInputs {
        double pixelError = 0.0;
        size_t detailBudget = 0;
        bool sourceDetail = false, water = false;
        float waterLevel = 0.0f, waterMargin = 0.0f;
        bool operator==(const LodInputs&) const = default;
    };
    LodInputs lodInputs_;
    LodInputs lodInputsOf(const WaterResources* water) const;
    // The working state (updateLod's): the last choice, its triangle list and, when the detail
    // patches changed, their vertices packed for the upload.
    LodChoice lastLod_;
    // The levels' triangles, then their skirt's, then the detail patches' and their skirt's.
    std::vector<uint32_t> lodIndices_;
    size_t lodMeshIndices_ = 0, lodSkirtEnd_ = 0, lodDetailEnd_ = 0;
    // Source resolution (kDetailVertexBudget): the source grid, the detail levels a patch has
    // (steps 2^d below the stride), each patch's levels' errors once measured, the patches the
    // detail buffer holds (their vertices, and where each starts) and its serial.
    lod::SourceGrid source_;
    uint8_t detailLevels_ = 0;
    std::vector<std::vector<double>> detailLevelErrors_;
    // What level d of patch k leaves out of the DEM (metres), measured once (updateLod's cache).
    double detailLevelError(uint32_t k, uint8_t d);
    std::map<uint32_t, std::vector<float>> detailVertices_;
    std::map<uint32_t, int8_t> detailHeld_;  // the detail level each held patch's vertices are for
    std::map<uint32_t, uint32_t> detailBase_;
    uint64_t detailSerial_ = 0;
    // Made where the levels are chosen (a worker's device memory is as good as the frame's): the
    // triangle list's index buffer, and where the device shares the host's memory, the detail
    // buffer; elsewhere every held patch's vertices in detailBase_ order, for the frame to upload.
    vk::Buffer lodIndexBuffer_, detailBuffer_;
    size_t lodIndexCount_ = 0;
    std::vector<float> detailUpload_;
    void buildLodBuffers(bool detailChanged);
    std::map<uint32_t, std::pair<uint64_t, double>> detailSurfaceCache_;  // per patch: its sides' key, its error
    size_t detailVertexBudget_ = kDetailVertexBudget;
    void chooseDetail(std::vector<int8_t>& detail, std::span<const uint8_t> levels, std::span<const double> surface,
                      std::span<const int8_t> finest, std::span<const double> asked, const glm::vec3& eye, double fovY,
                      double rows, double maxPixels, size_t budget);
    uint64_t lodSerial_ = 0;            // counts the index lists built
    // What the frames draw: the working state as last published, read by the frame's thread only.
    struct DrawnLod {
        LodChoice choice;
        size_t indexCount = 0, meshIndices = 0, skirtEnd = 0, detailEnd = 0;
        uint64_t serial = 0, detailSerial = 0;
        vk::Buffer indexBuffer, detailBuffer;  // until the frame takes them
        std::vector<float> detailVertices;     // until uploaded (no detailBuffer)
        uint32_t detailVertexCount = 0;
        bool picture = false;
        LodInputs inputs;
    };
    DrawnLod drawnLod_;
    void publishLod();
    // A choice under way on a worker, and what it was asked for: the camera, the rows, the view
    // and the inputs (a frame asking the same again starts nothing).
    struct LodKey {
        glm::vec3 eye{0.0f};
        double fovY = 0.0, rows = 0.0, sunUp = 0.0;
        bool picture = false, sourceDetail = false, shadowed = false;
        LodInputs inputs;
        bool operator==(const LodKey&) const = default;
    };
    std::future<void> pendingLod_;
    std::optional<LodKey> lodAsked_;
    void startLevelOfDetail(const RenderSettings& s, const LodKey& key);
    vk::VulkanContext& ctx_;
    const Heightfield& hf_;
    std::unique_ptr<RendererGpu> gpu_;
    int stride_ = 1;
    size_t vertexCount_ = 0, indexCount_ = 0, probeBytes_ = 0, reflectionBytes_ = 0;
    int volumeCount_ = 0;
    bool anyErrorMap_ = false;
    uint32_t markerCount_ = 0, leafCount_ = 0;
    float smallestLeaf_ = 1.0f;
    std::vector<float> meshVertices_;  // position and normal per vertex, as uploaded
    std::vector<Cascade> cascades_;
    size_t sunTraces_ = 0;
    // The horizon map's dimensions, its last sweep (and its packed bytes, which each frame slot
    // copies when its serial is behind), the sun and surface it was swept for.
    HorizonMapInfo horizonMap_;
    std::vector<float> sunHorizonMap_;
    std::vector<uint32_t> sunHorizonBytes_;
    glm::vec4 sunHorizonKey_{0.0f};
    int sunHorizonSkirt_ = -1;
    uint64_t sunHorizonSerial_ = 0;
    size_t sunHorizonSweeps_ = 0;
    // The sweep under way on a worker, for a sun and surface not yet held.
    struct PendingHorizon {
        glm::vec4 key{0.0f};
        bool skirt = false;
        std::future<SweptHorizon> perVertex;
    };
    std::unique_ptr<PendingHorizon> pendingHorizon_;
    bool hasAo_ = false, hasAlbedoMap_ = false;
    int skyImageHeight_ = 0;  // texels of the bound sky image, 0 without one
    float borderHeight_ = 0.0f;        // the DEM border's mean height: the skirt's, as the sky draws it
    glm::vec3 borderAlbedo_{1.0f};     // the albedo map's border ring, mean linear
    glm::ivec2 surfaceMapSize_{1, 1}, albedoMapSize_{1, 1};
    float finestProbeSpacing_ = 0.0f;  // of the bound volumes; 0 without
    FrameTimings timings_;
    Antialiasing drawnAntialiasing_ = Antialiasing::Off;
};

}  // namespace terralux
