#pragma once
// A render of the project's terrain, lit by the probes of the last bake in its output folder
// (baking first when that folder has none for the enabled volumes). `terralux --render`, the
// render tests and the UI viewport all come through here, so they draw the same image.

#include <chrono>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "DemImport.h"
#include "bake/DiffuseBake.h"
#include "bake/HeightfieldTracer.h"
#include "lpv/Lpv.h"
#include "Project.h"
#include "render/TerrainRenderer.h"
#include "terrain/HorizonAO.h"
#include "vk/VulkanContext.h"

namespace terralux {

struct RenderRequest {
    uint32_t width = 640, height = 360;
    int debugView = 0;
    bool probes = true;
    bool linearOutput = false;
    // The pixels as 8-bit codes (RenderedImage::bytes) rather than floats: a PNG's read-back.
    bool bytes = false;
    bool bakeIfMissing = true;
    bool probePositions = false;  // overlay of the enabled volumes' probe positions
    bool leaves = false;          // overlay of the adaptive volumes' octree leaves
    double time = 0.0;            // seconds: the phase of the water's waves
    std::vector<GizmoLine> gizmos;  // the viewport's volume bounds and handles
    // A viewport frame drawn below full resolution while the view changes (dynamic resolution),
    // which a full-resolution frame follows: it keeps the exposure last metered rather than
    // meter again (a meter is a frame of its own, which the device draws and reads back),
    // unless the view is the one the frame before it showed; the full-resolution frame meters.
    // Only present() reads it.
    bool interactive = false;
    // The window's size, where a viewport frame is drawn below it (0: width and height): the meter
    // reads the view at one size from that shape whatever the frame's scale, as a size rounded
    // from each scale's own shape differs by a row at some scales and would meter the view again.
    uint32_t windowWidth = 0, windowHeight = 0;
    // The rows the terrain's level of detail is chosen for (0: height): a viewport frame drawn
    // below full resolution keeps the full frame's levels and the shadow maps drawn for them,
    // unless its cascades moved (RenderSettings::levelOfDetailYields).
    uint32_t levelOfDetailRows = 0;
    // Off for the viewport: a sun edit's horizon map is swept on a worker while the frames draw
    // the one held (RenderSettings::waitForHorizon).
    bool waitForHorizon = true;
    // Off for the viewport: a new camera's levels of detail are chosen on a worker while the frames
    // draw the set held (RenderSettings::waitForLevelOfDetail).
    bool waitForLevelOfDetail = true;
    // Off for the viewport: a frame whose pipelines are not built yet starts their builds on a
    // worker (TerrainRenderer::pipelinesReady), a renderer's first frame that reads the horizon
    // map sweeps it on a worker (sunHorizonReady), its first picture chooses its levels of detail
    // on a worker (levelOfDetailReady), and its first metered frame draws its meter
    // behind the frames in flight; none is drawn until that is done (present()
    // returns false, waitingToDraw() holds meanwhile). On, the frame waits for them.
    bool waitUntilDrawable = true;
};

// The size the exposure meter draws a request at: `maxWidth` wide at most, the shape of the
// request's window (RenderRequest::windowWidth/Height) or, without one, of the request.
std::pair<uint32_t, uint32_t> meterSize(const RenderRequest& r, uint32_t maxWidth);

class ProjectRenderer;

// Which lighting scenario a render shows (docs/lighting.md, "Lighting scenarios"): `a`, or a
// blend from `a` toward `b` by `blend` in [0, 1] as an engine blends two baked scenarios: the
// probes' coefficients and the sky's SH linearly, the sun's direction along the arc between them.
// Names that the project no longer has show the default.
struct ScenarioView {
    std::string a = kDefaultScenario, b = kDefaultScenario;
    float blend = 0.0f;
    bool blends() const { return a != b && blend > 0.0f; }
};

// Coefficient by coefficient, (1 - t) a + t b: two bakes of the same layouts (names, grids and
// occupancy). Throws std::invalid_argument naming the volume whose layouts differ.
std::vector<GpuProbeVolume> blendProbeVolumes(const std::vector<GpuProbeVolume>& a,
                                              const std::vector<GpuProbeVolume>& b, float t);

// What one update of the light propagation volumes reads, held by value (the tracer and the albedo
// field shared), so that a worker can compute it while the project changes on the UI thread.
struct LpvJob {
    LpvSettings settings;
    std::vector<LocalLight> lights;
    BakeLighting lighting;
    std::shared_ptr<const HeightfieldTracer> tracer;  // lighting.tracer, kept alive
    glm::dvec3 eye{0.0}, viewDir{0.0, 0.0, -1.0};
    // The inputs and the cascades' placement: two jobs with equal keys compute equal volumes, so
    // a camera move within the cascades' cells computes nothing.
    std::string key;
    // Where the steps are taken: by the renderer that binds the volumes (Renderer), or here with
    // the geometry and the injection (Cpu). ProjectRenderer::lpvJob picks what its device does
    // faster (TerrainRenderer::propagatesLpv).
    lpv::Propagation propagation = lpv::Propagation::Cpu;
    std::shared_ptr<const lpv::Volumes> run() const { return run(propagation); }
    std::shared_ptr<const lpv::Volumes> run(lpv::Propagation where) const;
};

// How far the shadow maps are from the exact sun visibility: the shadow view (31) and the traced
// sun-visibility view (29) drawn scene-linear with the same camera, compared on terrain pixels.
struct ShadowAgreement {
    size_t terrainPixels = 0;
    double disagreeing = 0.0;     // share of terrain pixels where the two differ by more than 0.5
    double meanAbsDifference = 0.0;
    // Acne: of the pixels the tracer sees fully lit (at least 0.95), the share the maps darken
    // below 0.9. Self-shadowing shows here first, where the agreement barely moves.
    size_t tracedLitPixels = 0;
    double acne = 0.0;
    // The frame time of view 31 with its maps drawn in that frame (as a moving camera draws them).
    double shadowMilliseconds = 0.0;
    // Per screen tile of kShadowTile² pixels at least a quarter terrain: its share of disagreeing
    // terrain pixels (where the shadows go wrong, not only how often).
    std::vector<float> tileDisagreeing;
};
inline constexpr uint32_t kShadowTile = 32;
ShadowAgreement measureShadowAgreement(ProjectRenderer& renderer, uint32_t width, uint32_t height);

class ProjectRenderer {
public:
    // Loads the terrain and sky; the Vulkan context must outlive this object.
    ProjectRenderer(vk::VulkanContext& ctx, const Project& project);
    // With a terrain already imported (the UI holds one). `computeAo` false: the horizon AO of
    // the project is not computed here but handed in with setAmbientOcclusion (the UI computes
    // it off its thread); until then the terrain is drawn without AO.
    // `meshVertexBudget`: the drawn grid's vertices at most (TerrainRenderer's vertexBudget).
    ProjectRenderer(vk::VulkanContext& ctx, const Project& project, DemImportResult terrain,
                    bool computeAo = true, size_t meshVertexBudget = TerrainRenderer::kMeshVertexBudget);
    ~ProjectRenderer();

    // Reads sh_coeffs/<volume>.shprobe of every enabled volume from the output folder, with its
    // <volume>.probes.json diagnostics when present and matching, and the SH encoding the bake
    // wrote (from its report). When the bake there is missing or stale (its recorded inputs
    // differ from the project's, bakeInputs) and `rebake`, bakes the project first. Returns the
    // number of volumes bound; `note` says what was baked and why, `warnings` gets one line per
    // unreadable or stale diagnostics file; staleBake() says what differs when a stale bake
    // was drawn. `from`: another output folder to read (an export elsewhere; never baked
    // again); empty: the project's own.
    size_t loadProbes(bool rebake, std::string* note = nullptr,
                      std::vector<std::string>* warnings = nullptr,
                      const std::filesystem::path& from = {});
    // What differs between the bake loadProbes last drew and the project (empty: current).
    const std::vector<std::string>& staleBake() const { return staleBake_; }
    // Binds probe volumes computed elsewhere (the UI's draft preview).
    void setProbes(const std::vector<GpuProbeVolume>& volumes);
    // Binds a reflection-probe set (null: none) for the renderer to draw with; loadProbes binds
    // the bake's reflection/probes.rprobe while the project has reflection probes on.
    void setReflectionProbes(std::shared_ptr<const ReflectionProbeSet> set);
    const std::shared_ptr<const ReflectionProbeSet>& reflectionProbes() const { return reflections_; }
    // Probes of the bound volumes (what the viewport lights with), whatever the settings say now.
    size_t boundProbeCount() const { return boundProbes_; }
    // The bound volumes themselves, coefficients and diagnostics (the probe inspector reads them).
    std::shared_ptr<const std::vector<GpuProbeVolume>> boundVolumes() const { return boundVolumeData_; }
    // The scenario the renderer lights with (the sun, the sky; loadProbes then reads its probes).
    void setScenarioView(const ScenarioView& view);
    const ScenarioView& scenarioView() const { return view_; }
    // The view as drawn: names the project lacks replaced by the default, the blend in [0, 1]
    // (0 when both ends are the same scenario).
    ScenarioView shownView() const;
    // New lighting and camera settings of the same terrain (sun, sky, albedo, camera).
    // Also places the enabled volumes' probes again for the position overlay.
    void setProject(const Project& project);
    // A render draws the light propagation volumes when its view does (lighting.indirect lpv or
    // both with lpv.enabled, or an LPV debug view): render() computes them first for its camera
    // when the bound ones are not for it; present() draws what is bound (the viewport computes
    // them on a worker with lpvJob and binds them with setLpv).
    RenderedImage render(const RenderRequest& request);
    // The same render with an explicit camera (the viewport's).
    RenderedImage render(const RenderRequest& request, const OrbitCamera& camera);
    // The same frame into a window's swapchain, without reading it back or waiting for the GPU.
    // False when nothing was drawn: no swapchain image, or (waitUntilDrawable off) the frame's
    // pipelines, its first horizon map, its first levels of detail or its first meter reading are
    // still to come
    // (waitingToDraw).
    bool present(const RenderRequest& request, const OrbitCamera& camera, vk::Swapchain& swapchain);
    // Whether the last present() put its frame off (waitUntilDrawable off), and whether what it
    // waits for, pipelines building, the first horizon map or levels of detail on a worker, or the
    // first meter reading, is still to come:
    // the viewport asks for the frame again once it is not.
    bool deferredFrame() const { return deferredFrame_; }
    bool waitingToDraw() const;
    // The exposure the last frame showed, EV100: camera.ev100 in mode manual; in the metered modes
    // what the meter read (render) or the viewport's adaptation toward it (present); NaN before a
    // metered frame.
    double shownEv100() const;
    // The meter's last reading, EV100 (NaN before one).
    double meteredEv100() const { return meteredEv100_; }
    // Whether the last present() showed an exposure still adapting toward the meter (the
    // viewport draws another frame then).
    bool exposureAdapting() const { return adapting_; }
    // How often a frame was metered (edits and camera moves meter again; adaptation does not).
    size_t meterings() const { return meterings_; }
    // What a frame of `request` from `camera` is drawn with (the exposure aside, which render()
    // and present() set).
    RenderSettings settingsOf(const RenderRequest& request, const OrbitCamera& camera) const;

    // Whether a frame of `request` draws the LPV; a frame that does not frees bound volumes.
    bool drawsLpv(const RenderRequest& request) const;
    // The LPV update a frame of `request` from `camera` wants; nullopt when it draws no LPV.
    std::optional<LpvJob> lpvJob(const RenderRequest& request, const OrbitCamera& camera);
    // Binds volumes computed by a job (null: none) and remembers the job's key.
    void setLpv(std::shared_ptr<const lpv::Volumes> volumes, const std::string& key);
    const std::string& lpvKey() const { return lpvKey_; }
    // LPV updates this renderer computed itself (render()) or was handed (setLpv).
    size_t lpvUpdates() const { return lpvUpdates_; }
    const OrbitCamera& defaultCamera() const { return base_.camera; }
    // How often the probe volumes were placed for the overlays (edits that do not touch them
    // place nothing).
    size_t placements() const { return placements_; }
    // Whether any bound volume carries an interpolation-error map (the interpolation-error view
    // has data to show).
    bool hasErrorMap() const { return hasErrorMap_; }

    const Heightfield& heightfield() const { return terrain_.heightfield; }
    // The terrain albedo of the project (surfaceAlbedoOf): null in mode constant, and while the
    // project's albedo map cannot be read (albedoError() says why; the bake reports it too).
    const std::shared_ptr<const SurfaceAlbedo>& surfaceAlbedo() const { return albedo_; }
    const std::string& albedoError() const { return albedoError_; }
    // The horizon AO field the project asks for: its settings, or null when ao.enabled is off.
    std::optional<HorizonAoSettings> wantedAo() const;
    // Whether the bound AO field is the one the project asks for (or none is asked for).
    bool aoCurrent() const;
    // Binds a horizon AO field computed for `settings` over this renderer's terrain
    // (horizonSkyVisibility, one value per vertex).
    void setAmbientOcclusion(const HorizonAoSettings& settings, const std::vector<float>& field);
    // The same with its maps already made (TerrainRenderer::prepareSurfaceMaps, on a worker).
    void setAmbientOcclusion(const HorizonAoSettings& settings, TerrainRenderer::SurfaceMapTextures maps);
    TerrainRenderer& renderer() { return *renderer_; }

    // One volume's overlay records: probe markers and octree leaves.
    struct Overlay {
        std::vector<glm::vec4> markers, leaves;
    };

    // The widest the exposure meter draws a frame (meterSize).
    static constexpr uint32_t kMeterWidth = 128;

private:
    bool deferredFrame_ = false;
    // Per volume, the overlays follow the bound probes where they carry diagnostics and were
    // baked from the current probe-volume settings; otherwise the placement of those settings.
    void updateOverlays();
    // Whether a frame of `request` is metered (a metered mode, a picture view, display output).
    bool meters(const RenderRequest& request) const;
    // The EV100 the meter reads from `request`'s frame, drawn scene-linear kMeterWidth wide.
    double meter(const RenderRequest& request, const OrbitCamera& camera);
    // The frame the meter reads.
    RenderSettings meterSettings(const RenderRequest& request, const OrbitCamera& camera) const;
    // What a metering depends on: the bound inputs' revision, the view and the camera.
    std::string meterKey(const RenderRequest& request, const OrbitCamera& camera) const;
    static constexpr double kAdaptedEv = 0.02;  // closer than this to the meter is adapted

    Project project_;
    std::map<std::string, Overlay> placed_, bound_;  // by volume name
    Overlay shownOverlay_;  // what the renderer draws: an edit that leaves it uploads nothing
    std::shared_ptr<const std::vector<GpuProbeVolume>> boundVolumeData_ = std::make_shared<const std::vector<GpuProbeVolume>>();
    std::string boundVolumes_;  // probe_volumes JSON of the bound probes
    std::string placedVolumes_;  // probe_volumes JSON of placed_
    size_t placements_ = 0;
    size_t boundProbes_ = 0;
    bool hasErrorMap_ = false;
    std::vector<std::string> staleBake_;
    std::shared_ptr<const ReflectionProbeSet> reflections_;
    DemImportResult terrain_;
    std::shared_ptr<const SurfaceAlbedo> albedo_;
    std::string albedoError_;
    std::string albedoKey_;  // the terrain section albedo_ was made for
    const SurfaceAlbedo* uploadedAlbedo_ = nullptr;  // the field the renderer holds
    bool computeAo_ = true;
    std::optional<HorizonAoSettings> boundAo_;  // the settings of the bound AO field
    RenderSettings base_;
    ScenarioView view_;
    BakeLighting shown_;  // the lighting of the scenario shown (the blend's nearer end)
    std::optional<Sky> heldSky_;  // the sky whose image the renderer holds
    std::string blendedSkyKey_;   // while it holds two scenarios' skies mixed: which, and how
    std::unique_ptr<TerrainRenderer> renderer_;
    std::shared_ptr<const HeightfieldTracer> tracer_;  // for the LPV, made on first use
    std::string lpvKey_;
    size_t lpvUpdates_ = 0;
    size_t revision_ = 0;  // bumped by every change of what a frame shows but the camera
    std::string meterKey_;
    std::string pendingMeterKey_;  // what the meter frame the device is drawing (present()) reads
    std::string lastFrameKey_;  // the meter key of the frame present() drew last
    double meteredEv100_ = std::numeric_limits<double>::quiet_NaN();
    double shownEv100_ = std::numeric_limits<double>::quiet_NaN();
    std::chrono::steady_clock::time_point shownAt_;
    bool adapting_ = false;
    size_t meterings_ = 0;
};

// Why the bake in `folder` is not `project`'s: the differences between its recorded inputs and the
// project's (bakeInputs), or what is missing; empty when it is current.
std::vector<std::string> bakeStaleness(const Project& project, const std::filesystem::path& folder);

}  // namespace terralux
