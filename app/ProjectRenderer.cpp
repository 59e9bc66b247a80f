#include "ProjectRenderer.h"

#include <chrono>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <tuple>
#include <utility>

#include "AlbedoImport.h"
#include "BakeJob.h"
#include "KeptPlacement.h"
#include "ParameterTable.h"
#include "SceneLighting.h"
#include "ProbeDiagnosticsFile.h"
#include "ReflectionProbeFile.h"
#include "ShProbeFile.h"
#include "TerrainLoading.h"
#include "bake/ProbePlacement.h"
#include "scene/Exposure.h"
#include "lpv/Lpv.h"
#include "scene/DebugViews.h"
#include "scene/OrbitCamera.h"

namespace terralux {

namespace {

// Overlay markers (w 1 = valid, 2 = moved up, 0 = rejected inside the terrain) and leaves.
ProjectRenderer::Overlay overlayOf(const ProbeDiagnostics& d) {
    ProjectRenderer::Overlay o;
    for (size_t i = 0; i < d.positions.size(); ++i)
        o.markers.emplace_back(d.positions[i], i < d.moved.size() && d.moved[i] ? 2.0f : 1.0f);
    for (const auto& p : d.rejected) o.markers.emplace_back(p, 0.0f);
    o.leaves = d.leaves;
    return o;
}

}  // namespace

ProjectRenderer::ProjectRenderer(vk::VulkanContext& ctx, const Project& project)
    : ProjectRenderer(ctx, project, loadProjectTerrain(project)) {}

ProjectRenderer::ProjectRenderer(vk::VulkanContext& ctx, const Project& project,
                                 DemImportResult terrain, bool computeAo, size_t meshVertexBudget)
    : project_(project), terrain_(std::move(terrain)), computeAo_(computeAo) {
    renderer_ = std::make_unique<TerrainRenderer>(ctx, terrain_.heightfield, meshVertexBudget);
    setProject(project);
}

std::vector<GpuProbeVolume> blendProbeVolumes(const std::vector<GpuProbeVolume>& a,
                                              const std::vector<GpuProbeVolume>& b, float t) {
    std::vector<GpuProbeVolume> out = a;
    for (size_t v = 0; v < out.size(); ++v) {
        if (v >= b.size() || b[v].name != a[v].name || b[v].dims != a[v].dims || b[v].origin != a[v].origin ||
            b[v].spacing != a[v].spacing || b[v].occupancy != a[v].occupancy || b[v].coeffs.size() != a[v].coeffs.size())
            throw std::invalid_argument("probe volume '" + a[v].name + "': the two scenarios' layouts differ");
        for (size_t i = 0; i < out[v].coeffs.size(); ++i)
            for (size_t k = 0; k < 9; ++k) out[v].coeffs[i][k] = glm::mix(a[v].coeffs[i][k], b[v].coeffs[i][k], t);
    }
    return out;
}

ScenarioView ProjectRenderer::shownView() const {
    ScenarioView v{knownScenario(project_.scene, view_.a), knownScenario(project_.scene, view_.b),
                   std::clamp(view_.blend, 0.0f, 1.0f)};
    if (v.a == v.b) v.blend = 0.0f;
    return v;
}

void ProjectRenderer::setScenarioView(const ScenarioView& view) {
    view_ = view;
    setProject(project_);
}

void ProjectRenderer::setProject(const Project& project) {
    project_ = project;
    ++revision_;
    const SceneDescription& scene = project_.scene;
    const Heightfield& hf = terrain_.heightfield;
    const ScenarioView shown = shownView();
    const std::string &a = shown.a, &b = shown.b;
    const float t = shown.blend;
    Project litA = project_, litB = project_;
    litA.scene = scenarioScene(scene, a);
    litB.scene = scenarioScene(scene, b);
    const BakeLighting lighting = lightingOf(t < 0.5f ? litA : litB, hf);
    shown_ = lighting;
    const bool blending = t > 0.0f && t < 1.0f;
    std::optional<BakeLighting> la, lb;
    if (blending) la = lightingOf(litA, hf), lb = lightingOf(litB, hf);
    // The sky behind the terrain at full resolution: the shown scenario's image, uploaded when it
    // is another one (not for an edit of its intensity); between two scenarios whose skies are
    // not both uniform, the two skies mixed into one image, made again when either or the blend
    // changes.
    int skyWidth = 0, skyHeight = 0;
    const std::vector<glm::vec3>* skyImage = lighting.sky.image(&skyWidth, &skyHeight);
    // Both ends' sizes: the blend is drawn at the finer of the two.
    int widthA = 0, heightA = 0, widthB = 0, heightB = 0;
    const bool imageA = blending && la->sky.image(&widthA, &heightA) != nullptr;
    const bool imageB = blending && lb->sky.image(&widthB, &heightB) != nullptr;
    if (imageA || imageB) {
        std::ostringstream key;
        for (const BakeLighting* l : {&*la, &*lb}) {
            int w = 0, h = 0;
            const glm::vec3 s = l->sky.scale(), up = l->sky.radiance(glm::vec3(0.0f, 1.0f, 0.0f));
            key << static_cast<const void*>(l->sky.image(&w, &h)) << ' ' << s.x << ' ' << s.y << ' ' << s.z << ' '
                << l->sky.rotationTurns() << ' ' << up.x << ' ' << up.y << ' ' << up.z << ' ';
        }
        key << t;
        if (key.str() != blendedSkyKey_) {
            // The finer of the two images, at most a 2048 x 1024 equirectangular one.
            const int w = std::min(std::max(widthA, widthB), 2048), h = std::min(std::max(heightA, heightB), 1024);
            renderer_->setSkyImage(w, h, blendedEquirect(la->sky, lb->sky, t, w, h));
            heldSky_.reset();
            blendedSkyKey_ = key.str();
        }
        base_.skyImageScale = glm::vec3(1.0f);
        base_.skyImageRotation = 0.0f;
    } else {
        int heldWidth = 0, heldHeight = 0;
        if (!blendedSkyKey_.empty() || skyImage != (heldSky_ ? heldSky_->image(&heldWidth, &heldHeight) : nullptr)) {
            renderer_->setSkyImage(skyImage ? skyWidth : 0, skyImage ? skyHeight : 0,
                                   skyImage ? *skyImage : std::vector<glm::vec3>{});
            heldSky_ = lighting.sky;  // holds the texels, so no other image can take their address
            blendedSkyKey_.clear();
        }
        base_.skyImageScale = lighting.sky.scale();
        base_.skyImageRotation = lighting.sky.rotationTurns();
    }
    base_.albedo = lighting.albedo;
    base_.terrain = scene.terrain;
    base_.detail = scene.detail;
    // The terrain is this renderer's for good: only an edit of the terrain section (or, in mode
    // map, of the file, which surfaceAlbedoOf notices) makes a new field, not a camera move.
    nlohmann::json terrainSection = sceneToJson(scene).at("terrain");
    for (const char* shading : {"roughness", "specular_aa", "skirt"}) terrainSection.erase(shading);
    const std::string albedoKey = terrainSection.dump();
    if (albedoKey != albedoKey_ || scene.terrain.albedoMode == AlbedoMode::Map) {
        albedoKey_ = albedoKey;
        // A map that cannot be read leaves the constant albedo on screen rather than no picture.
        albedoError_.clear();
        try {
            albedo_ = surfaceAlbedoOf(project_, terrain_.heightfield);
        } catch (const ImageError& e) {
            albedo_.reset();
            albedoError_ = e.what();
        }
    }
    if (albedo_.get() != uploadedAlbedo_) {
        uploadedAlbedo_ = albedo_.get();
        if (albedo_)
            renderer_->setAlbedoMap(albedo_->width, albedo_->height, albedo_->srgb);
        else
            renderer_->setAlbedoMap(0, 0, {});
    }
    base_.ao = scene.ao;
    if (computeAo_ && !aoCurrent()) {
        const HorizonAoSettings wanted = *wantedAo();
        setAmbientOcclusion(wanted, horizonSkyVisibility(terrain_.heightfield, wanted));
    }
    base_.camera = OrbitCamera::fromSettings(scene.camera, terrain_.heightfield);
    // Metered modes replace this per frame (exposed).
    base_.exposure = float(exposureScale(scene.camera.ev100, scene.camera.exposureEv));
    base_.antialiasing = scene.camera.antialiasing;
    base_.shadows = scene.shadows;
    if (!blending) {
        base_.sun = lighting.sun;
        base_.skySh = lighting.sky.sh();
        base_.fog = resolvedFog(scene.fog, lighting.sky, hf);
    } else {
        // Between two scenarios: the sun turns along the arc between its two directions (nlerp),
        // its illuminance and size and the sky's SH mix linearly, as the probes do.
        const glm::vec3 d = glm::mix(la->sun.direction, lb->sun.direction, t);
        base_.sun = la->sun;
        base_.sun.direction = glm::length(d) > 1e-4f ? glm::normalize(d) : (t < 0.5f ? la->sun.direction : lb->sun.direction);
        base_.sun.illuminance = glm::mix(la->sun.illuminance, lb->sun.illuminance, t);
        base_.sun.angularRadius = glm::mix(la->sun.angularRadius, lb->sun.angularRadius, t);
        const sh::ShRgb sa = la->sky.sh(), sb = lb->sky.sh();
        for (size_t k = 0; k < sa.c.size(); ++k) base_.skySh.c[k] = glm::mix(sa.c[k], sb.c[k], t);
        const FogSettings fa = resolvedFog(scene.fog, la->sky, hf), fb = resolvedFog(scene.fog, lb->sky, hf);
        base_.fog = fa;
        base_.fog.setAmbientRadiance(glm::mix(fa.ambientRadiance(), fb.ambientRadiance(), t));
    }
    base_.skirt = scene.terrain.skirt;
    base_.reflectionStrength = float(scene.reflectionProbes.strength);
    const IndirectLighting indirect = scene.lighting.indirect;
    base_.lpvLight = scene.lpv.enabled && (indirect == IndirectLighting::Lpv || indirect == IndirectLighting::Both);
    base_.lights = scene.lights;
    // Water: the level and the highest crest decide the field and the mesh (built again only when
    // they change); everything else is uniforms.
    const WaterSettings& ws = scene.water;
    base_.water = ws;
    std::optional<double> level;
    double crest = 0.0;
    if (ws.enabled) {
        for (const GerstnerWave& wave : ws.waves) crest += water::waveTerms(wave).amplitude;
        level = water::waterLevel(ws, terrain_.heightfield);  // "auto" may find no water: none is drawn
    }
    renderer_->setWater(level ? std::optional<float>(float(*level)) : std::nullopt, float(crest));
    // Placement reads only the volumes' settings and this renderer's terrain: edits of the sun,
    // sky or camera keep the markers they had.
    const std::string volumes = sceneToJson(scene).at("probe_volumes").dump();
    if (volumes == placedVolumes_) return updateOverlays();
    placedVolumes_ = volumes;
    ++placements_;
    placed_.clear();
    for (size_t i = 0; i < scene.probeVolumes.size(); ++i) {
        const auto& v = scene.probeVolumes[i];
        if (!v.enabled) continue;
        try {
            placed_[v.name] = overlayOf(describeProbes(*keptPlacement(scene, i, terrain_.heightfield)));
        } catch (const PlacementError&) {
            // Settings the bake would refuse: no markers for that volume.
        }
    }
    updateOverlays();
}

std::optional<HorizonAoSettings> ProjectRenderer::wantedAo() const {
    const AoSettings& ao = project_.scene.ao;
    if (!ao.enabled) return std::nullopt;
    return HorizonAoSettings{ao.directions, ao.maxDistance.value_or(0.0)};
}

bool ProjectRenderer::aoCurrent() const {
    const auto wanted = wantedAo();
    if (!wanted) return true;
    return boundAo_ && boundAo_->directions == wanted->directions && boundAo_->maxDistance == wanted->maxDistance;
}

void ProjectRenderer::setAmbientOcclusion(const HorizonAoSettings& settings, const std::vector<float>& field) {
    renderer_->setAmbientOcclusion(field);
    boundAo_ = settings;
    ++revision_;
}

void ProjectRenderer::setAmbientOcclusion(const HorizonAoSettings& settings, TerrainRenderer::SurfaceMapTextures maps) {
    renderer_->setSurfaceMaps(std::move(maps));
    boundAo_ = settings;
    ++revision_;
}

void ProjectRenderer::setProbes(const std::vector<GpuProbeVolume>& volumes) {
    renderer_->setProbeVolumes(volumes);
    ++revision_;
    boundVolumeData_ = std::make_shared<const std::vector<GpuProbeVolume>>(volumes);
    boundProbes_ = 0;
    for (const auto& v : volumes) boundProbes_ += v.coeffs.size();
    bound_.clear();
    boundVolumes_ = sceneToJson(project_.scene).at("probe_volumes").dump();
    hasErrorMap_ = false;
    for (const auto& v : volumes) {
        if (!v.diagnostics) continue;
        bound_[v.name] = overlayOf(*v.diagnostics);
        hasErrorMap_ = hasErrorMap_ || !v.diagnostics->errorMap.empty();
    }
    updateOverlays();
}

void ProjectRenderer::setReflectionProbes(std::shared_ptr<const ReflectionProbeSet> set) {
    reflections_ = set;
    ++revision_;
    renderer_->setReflectionProbes(std::move(set));
}

void ProjectRenderer::updateOverlays() {
    const bool current = boundVolumes_ == sceneToJson(project_.scene).at("probe_volumes").dump();
    std::vector<glm::vec4> markers, leaves;
    for (const auto& v : project_.scene.probeVolumes) {
        if (!v.enabled) continue;
        const auto b = bound_.find(v.name);
        const auto p = placed_.find(v.name);
        const Overlay* o = current && b != bound_.end() ? &b->second
                           : p != placed_.end()          ? &p->second
                                                         : nullptr;
        if (!o) continue;
        markers.insert(markers.end(), o->markers.begin(), o->markers.end());
        leaves.insert(leaves.end(), o->leaves.begin(), o->leaves.end());
    }
    if (markers != shownOverlay_.markers) renderer_->setProbePositions(markers);
    if (leaves != shownOverlay_.leaves) renderer_->setProbeLeaves(leaves);
    shownOverlay_ = {std::move(markers), std::move(leaves)};
}

ProjectRenderer::~ProjectRenderer() = default;

namespace {

nlohmann::json readReport(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) return nullptr;
    nlohmann::json report = nlohmann::json::parse(in, nullptr, false);
    return report.is_object() ? report : nlohmann::json(nullptr);
}

// The fallback blend distance the bake resolved for a volume, when its report names the volume.
std::optional<float> reportedBlendDistance(const nlohmann::json& report, const std::string& volume) {
    if (!report.is_object() || !report.contains("volumes") || !report["volumes"].is_array()) return std::nullopt;
    for (const auto& v : report["volumes"])
        if (v.is_object() && v.value("name", std::string()) == volume && v.contains("fallback_blend_distance") &&
            v["fallback_blend_distance"].is_number())
            return v["fallback_blend_distance"].get<float>();
    return std::nullopt;
}

// Why the bake in the folder is not the project's: its differences, or what is missing.
std::vector<std::string> staleness(const Project& project, const std::filesystem::path& dir,
                                   const nlohmann::json& report) {
    for (const auto& v : project.scene.probeVolumes)
        if (v.enabled && !std::filesystem::exists(dir / "sh_coeffs" / (v.name + ".shprobe")))
            return {"no sh_coeffs/" + v.name + ".shprobe"};
    if (report.is_null()) return {"no readable bake_report.json"};
    if (!report.contains("inputs")) return {"bake_report.json records no inputs (an older bake)"};
    return bakeInputDifferences(report["inputs"], bakeInputs(project));
}

std::string summary(const std::vector<std::string>& differences) {
    std::string s = differences.front();
    if (differences.size() > 1) s += " and " + std::to_string(differences.size() - 1) + " more";
    return s;
}

}  // namespace

std::vector<std::string> bakeStaleness(const Project& project, const std::filesystem::path& folder) {
    return staleness(project, folder, readReport(folder / "bake_report.json"));
}

size_t ProjectRenderer::loadProbes(bool rebake, std::string* note, std::vector<std::string>* warnings,
                                   const std::filesystem::path& from) {
    const SceneDescription& scene = project_.scene;
    const std::filesystem::path folder = from.empty() ? project_.outDir() : from;
    const std::filesystem::path dir = folder / "sh_coeffs";
    nlohmann::json report = readReport(folder / "bake_report.json");
    staleBake_ = staleness(project_, folder, report);
    // Only the project's own folder is baked again; another folder is drawn as it is.
    if (!staleBake_.empty() && rebake && from.empty()) {
        BakeRequest request;
        request.project = project_;
        runBake(request, nullptr, nullptr);
        if (note) *note = "baked " + project_.outDir().string() + " first (" +
                          (report.is_null() ? std::string("no earlier bake there") : "the bake there is stale: " + summary(staleBake_)) + ")";
        report = readReport(project_.outDir() / "bake_report.json");
        staleBake_.clear();
    }
    // The encoding the probes were written in, not the one the project asks for now.
    const bool irradiance = report.is_object() && report.contains("sh_encoding")
                                ? report["sh_encoding"] == "irradiance"
                                : scene.bake.encoding == ShEncoding::Irradiance;
    // The scenarios shown: the default's files are sh_coeffs/, another's scenarios/.
    const ScenarioView shown = shownView();
    const std::string &shownA = shown.a, &shownB = shown.b;
    auto scenarioFile = [&](const std::string& volume, const std::string& scenario) {
        return scenario == kDefaultScenario ? dir / (volume + ".shprobe")
                                            : folder / "scenarios" / (volume + "." + scenario + ".shprobe");
    };
    auto coefficientsOf = [&](const std::string& volume, const std::string& scenario, const ShProbeGrid& layout) {
        const ShProbeGrid g = readShProbeFile(scenarioFile(volume, scenario));
        if (g.dims != layout.dims || g.occupancy != layout.occupancy)
            throw ShProbeError(scenarioFile(volume, scenario).string() + ": not the layout of sh_coeffs/" + volume +
                               ".shprobe (bake again)");
        std::vector<std::array<glm::vec3, 9>> c;
        for (const auto& r : g.probes) c.push_back(r.coeffs);
        return c;
    };
    std::vector<GpuProbeVolume> volumes, towards;
    for (const auto& v : scene.probeVolumes) {
        if (!v.enabled) continue;
        const auto path = dir / (v.name + ".shprobe");
        if (!std::filesystem::exists(path)) continue;
        if (!std::filesystem::exists(scenarioFile(v.name, shownA)) || !std::filesystem::exists(scenarioFile(v.name, shownB))) {
            if (warnings)
                warnings->push_back(scenarioFile(v.name, std::filesystem::exists(scenarioFile(v.name, shownA)) ? shownB : shownA).string() +
                                    ": missing (bake again for the scenario)");
            continue;
        }
        std::vector<uint8_t> bytes;
        const ShProbeGrid g = readShProbeFile(path, &bytes);
        GpuProbeVolume gv;
        gv.name = v.name;
        gv.dims = g.dims;
        gv.origin = g.origin;
        gv.spacing = g.spacing;
        gv.occupancy = g.occupancy;
        gv.scale = g.defaultScale;
        gv.irradianceEncoded = irradiance;
        // The distance the bake resolved (defaultFallbackBlendDistance), from its report; a folder
        // without one falls back to twice the file's cell edge, the grid's smallest spacing.
        gv.fallbackBlendDistance = v.fallbackBlendDistance ? float(*v.fallbackBlendDistance)
                                                           : reportedBlendDistance(report, v.name).value_or(2.0f * g.spacing);
        if (shownA == kDefaultScenario)
            for (const auto& r : g.probes) gv.coeffs.push_back(r.coeffs);
        else
            gv.coeffs = coefficientsOf(v.name, shownA, g);
        if (shown.blends()) {
            towards.push_back(gv);
            towards.back().coeffs = coefficientsOf(v.name, shownB, g);
        }
        // The diagnostics (moved probes, the interpolation-error map) are the layout's, measured
        // under the default's light.
        const auto sidecar = dir / probeDiagnosticsFileName(v.name);
        try {
            if (std::filesystem::exists(sidecar))
                gv.diagnostics = readProbeDiagnosticsFile(sidecar, g, shProbeDigest(bytes));
            else if (warnings)
                warnings->push_back(sidecar.string() + ": missing (bake again for " + diagnosticsViewList() + ")");
        } catch (const ProbeDiagnosticsError& e) {
            if (warnings) warnings->push_back(e.what());
        }
        volumes.push_back(std::move(gv));
        if (shown.blends()) towards.back().diagnostics = volumes.back().diagnostics;
    }
    setProbes(shown.blends() ? blendProbeVolumes(volumes, towards, shown.blend) : volumes);
    // The reflection probes the bake wrote, while the project has them on.
    std::shared_ptr<const ReflectionProbeSet> reflections;
    const auto rprobe = folder / "reflection" / kReflectionProbeFile;
    if (scene.reflectionProbes.enabled) {
        try {
            if (std::filesystem::exists(rprobe))
                reflections = std::make_shared<const ReflectionProbeSet>(readReflectionProbeFile(rprobe));
            else if (warnings)
                warnings->push_back(rprobe.string() + ": missing (bake again with reflection_probes.enabled)");
        } catch (const ReflectionFileError& e) {
            if (warnings) warnings->push_back(e.what());
        }
    }
    setReflectionProbes(std::move(reflections));
    return volumes.size();
}

RenderedImage ProjectRenderer::render(const RenderRequest& r) { return render(r, base_.camera); }

RenderedImage ProjectRenderer::render(const RenderRequest& r, const OrbitCamera& camera) {
    if (!drawsLpv(r)) setLpv(nullptr, "");
    else if (const std::optional<LpvJob> job = lpvJob(r, camera); job && job->key != lpvKey_) setLpv(job->run(), job->key);
    RenderSettings s = settingsOf(r, camera);
    if (meters(r)) {
        // A render shows the metered exposure itself, as an adapted eye would; the viewport
        // adapts from there.
        meteredEv100_ = shownEv100_ = meter(r, camera);
        meterKey_ = meterKey(r, camera);
        shownAt_ = std::chrono::steady_clock::now();
        s.exposure = float(exposureScale(shownEv100_, project_.scene.camera.exposureEv));
    }
    return renderer_->render(s);
}

bool ProjectRenderer::meters(const RenderRequest& r) const {
    // Scene-linear output (EXR) is not exposed.
    if (project_.scene.camera.exposureMode == ExposureMode::Manual || r.linearOutput) return false;
    const std::optional<DebugView> view = findDebugView(r.debugView);
    return view && view->background != ViewBackground::Black;
}

// The viewport's dynamic resolution draws the same view at several sizes, all of one meter size.
std::pair<uint32_t, uint32_t> meterSize(const RenderRequest& r, uint32_t maxWidth) {
    const bool window = r.windowWidth > 0 && r.windowHeight > 0;
    const uint32_t width = window ? r.windowWidth : r.width, height = window ? r.windowHeight : r.height;
    const uint32_t w = std::min(width, maxWidth);
    return {w, std::max(1u, uint32_t(std::lround(double(height) * w / std::max(1u, width))))};
}

std::string ProjectRenderer::meterKey(const RenderRequest& r, const OrbitCamera& camera) const {
    std::ostringstream key;
    const auto [w, h] = meterSize(r, kMeterWidth);
    key << revision_ << ' ' << r.debugView << ' ' << r.probes << ' ' << w << 'x' << h
        << ' ' << camera.target.x << ' ' << camera.target.y << ' ' << camera.target.z << ' ' << camera.radius << ' '
        << camera.azimuthDeg << ' ' << camera.elevationDeg << ' ' << camera.fovDeg;
    return key.str();
}

RenderSettings ProjectRenderer::meterSettings(const RenderRequest& r, const OrbitCamera& camera) const {
    // The meter reads the frame's own scene-linear light at a small size: a mean over ten
    // thousand pixels moves by far less than the 0.1 EV a viewer notices.
    RenderRequest q = r;
    std::tie(q.width, q.height) = meterSize(r, kMeterWidth);
    q.linearOutput = true;
    q.bytes = false;
    q.probePositions = q.leaves = false;
    q.gizmos.clear();
    RenderSettings s = settingsOf(q, camera);
    s.antialiasing = Antialiasing::Off;
    s.levelOfDetailRows = r.levelOfDetailRows > 0 ? r.levelOfDetailRows : r.height;
    s.levelOfDetailYields = false;
    return s;
}

double ProjectRenderer::meter(const RenderRequest& r, const OrbitCamera& camera) {
    const RenderedImage img = renderer_->render(meterSettings(r, camera));
    // A meter the viewport began before reads an older frame: this reading replaces it.
    (void)renderer_->takeOffscreen();
    ++meterings_;
    return meterEv100(img.rgba, img.width, img.height, project_.scene.camera.exposureMode);
}

double ProjectRenderer::shownEv100() const {
    return project_.scene.camera.exposureMode == ExposureMode::Manual ? project_.scene.camera.ev100 : shownEv100_;
}

bool ProjectRenderer::drawsLpv(const RenderRequest& r) const {
    const std::optional<DebugView> view = findDebugView(r.debugView);
    return view && ((base_.lpvLight && view->needs.sceneLights) || view->needs.lpvVolumes);
}

std::optional<LpvJob> ProjectRenderer::lpvJob(const RenderRequest& r, const OrbitCamera& camera) {
    if (!drawsLpv(r)) return std::nullopt;
    const SceneDescription& scene = project_.scene;
    const bool skirt = scene.terrain.skirt;
    if (!tracer_ || tracer_->options().skirt != skirt) {
        HeightfieldTracer::Options o;
        o.skirt = skirt;
        tracer_ = std::make_shared<const HeightfieldTracer>(terrain_.heightfield, o);
    }
    LpvJob job;
    job.settings = lpv::resolvedOn(scene.lpv, terrain_.heightfield);
    job.lights = scene.lights;
    job.lighting = shown_;
    job.lighting.surface = albedo_;
    job.tracer = tracer_;
    job.lighting.tracer = tracer_.get();
    job.eye = glm::dvec3(camera.lpvEye());
    job.viewDir = glm::dvec3(camera.lpvViewDirection());
    job.propagation = renderer_->propagatesLpv() ? lpv::Propagation::Renderer : lpv::Propagation::Cpu;
    const nlohmann::json sceneJson = sceneToJson(scene);
    nlohmann::json key = {{"albedo", reinterpret_cast<uintptr_t>(albedo_.get())}};
    for (const char* section : {"lpv", "lights", "sun", "sky", "terrain", "scenarios"}) key[section] = sceneJson.value(section, nlohmann::json());
    key["scenario"] = {view_.a, view_.b, view_.blend < 0.5f};
    for (const lpv::CascadeLayout& c : lpv::placeCascades(job.settings, job.eye, job.viewDir))
        key["cascades"].push_back({c.originCell[0], c.originCell[1], c.originCell[2]});
    job.key = key.dump();
    return job;
}

std::shared_ptr<const lpv::Volumes> LpvJob::run(lpv::Propagation where) const {
    return std::make_shared<const lpv::Volumes>(settings, lpv::Inputs{&lighting, &lights}, eye, viewDir, where);
}

void ProjectRenderer::setLpv(std::shared_ptr<const lpv::Volumes> volumes, const std::string& key) {
    if (volumes) ++lpvUpdates_;
    // Only a change of the volumes changes the frame; present() clears them on every frame that
    // draws none, and that must not meter again.
    if (volumes != renderer_->lpv()) ++revision_;
    lpvKey_ = volumes ? key : std::string();
    renderer_->setLpv(std::move(volumes));
}

bool ProjectRenderer::present(const RenderRequest& r, const OrbitCamera& camera, vk::Swapchain& swapchain) {
    if (!drawsLpv(r)) setLpv(nullptr, "");  // volumes no frame draws hold no memory
    RenderSettings s = settingsOf(r, camera);
    // Nothing is drawn, and nothing metered, until the frame's pipelines and its meter's are
    // built: the window keeps the frame it shows meanwhile.
    deferredFrame_ = false;
    if (!r.waitUntilDrawable) {
        bool ready = renderer_->pipelinesReady(s);
        if (meters(r)) ready = renderer_->pipelinesReady(meterSettings(r, camera)) && ready;
        ready = renderer_->sunHorizonReady(s) && ready;  // the meter reads the same sun's map
        ready = renderer_->levelOfDetailReady(s) && ready;
        if (!ready) {
            deferredFrame_ = true;
            return false;
        }
    }
    if (!meters(r)) adapting_ = false;
    else {
        // Metered again only when what the frame shows changed; the shown exposure follows the
        // meter with the authored time constant, frame after frame.
        // A frame below full resolution meters only once the view holds still (the key of the
        // frame before it): while it changes, the full-resolution frame that follows meters, and
        // frames that keep coming for other reasons (the water's waves playing) meter the still view.
        const std::string key = meterKey(r, camera);
        const bool still = key == lastFrameKey_;
        lastFrameKey_ = key;
        // The meter is a frame the device draws behind the viewport's without anyone waiting
        // (a wait held the window 70-110 ms a metering on a CPU device): a frame after it lands
        // its reading is taken, and the shown exposure adapts toward it from there.
        if (std::optional<RenderedImage> img = renderer_->takeOffscreen()) {
            meteredEv100_ = meterEv100(img->rgba, img->width, img->height, project_.scene.camera.exposureMode);
            meterKey_ = pendingMeterKey_;
            ++meterings_;
        }
        if (key != meterKey_ && (!r.interactive || still || std::isnan(meteredEv100_))) {
            if (std::isnan(meteredEv100_)) {
                // The first frame has no reading to show: it waits for its own (the viewport's
                // behind the frames in flight, without holding the UI thread; 180 ms on lavapipe).
                if (r.waitUntilDrawable) {
                    meteredEv100_ = meter(r, camera);
                    meterKey_ = key;
                } else {
                    if (!renderer_->offscreenPending()) {
                        renderer_->beginOffscreen(meterSettings(r, camera));
                        pendingMeterKey_ = key;
                    }
                    deferredFrame_ = true;
                    adapting_ = true;  // the eye has a reading to come
                    return false;
                }
            } else if (!renderer_->offscreenPending()) {
                renderer_->beginOffscreen(meterSettings(r, camera));
                pendingMeterKey_ = key;
            }
        }
        // An adapted eye starts adapting at the first frame of a change, however long the
        // viewport was idle before it.
        const auto now = std::chrono::steady_clock::now();
        const double seconds = adapting_ ? std::chrono::duration<double>(now - shownAt_).count() : 0.0;
        shownEv100_ = adaptEv100(shownEv100_, meteredEv100_, seconds, project_.scene.camera.adaptationSeconds);
        shownAt_ = now;
        // A reading still to come keeps the frames coming, as adapting does.
        adapting_ = std::abs(shownEv100_ - meteredEv100_) > kAdaptedEv || renderer_->offscreenPending();
        s.exposure = float(exposureScale(shownEv100_, project_.scene.camera.exposureEv));
    }
    return renderer_->present(s, swapchain);
}

bool ProjectRenderer::waitingToDraw() const {
    return renderer_->pipelinesBuilding() || renderer_->sunHorizonAwaited() || renderer_->levelOfDetailAwaited() ||
           (std::isnan(meteredEv100_) && renderer_->offscreenPending() && !renderer_->offscreenFinished());
}

RenderSettings ProjectRenderer::settingsOf(const RenderRequest& r, const OrbitCamera& camera) const {
    RenderSettings s = base_;
    s.camera = camera;
    s.width = r.width;
    s.height = r.height;
    s.debugView = r.debugView;
    // lighting.indirect: the probes light the frame in probes and both, the LPV (base_.lpvLight)
    // in lpv and both; none draws the frame without either, as with probes off.
    const IndirectLighting indirect = project_.scene.lighting.indirect;
    s.probes = r.probes && (indirect == IndirectLighting::Probes || indirect == IndirectLighting::Both);
    s.linearOutput = r.linearOutput;
    s.readbackBytes = r.bytes && !r.linearOutput;
    s.showProbePositions = r.probePositions;
    s.showLeaves = r.leaves;
    s.gizmos = r.gizmos;
    s.time = r.time;
    s.levelOfDetailRows = r.levelOfDetailRows;
    s.levelOfDetailYields = r.levelOfDetailRows > r.height;  // a frame below full resolution
    s.waitForHorizon = r.waitForHorizon;
    s.waitForLevelOfDetail = r.waitForLevelOfDetail;
    return s;
}

ShadowAgreement measureShadowAgreement(ProjectRenderer& renderer, uint32_t width, uint32_t height) {
    RenderRequest q;
    q.width = width;
    q.height = height;
    q.linearOutput = true;
    q.probes = false;
    q.debugView = kViewSunVisibility;
    const RenderedImage traced = renderer.render(q);
    q.debugView = kViewShadow;
    renderer.render(q);  // the first frame of a new view may build its pipeline: not its time
    renderer.renderer().redrawShadowMaps();
    const RenderedImage mapped = renderer.render(q);
    ShadowAgreement a;
    a.shadowMilliseconds = mapped.milliseconds;
    const uint32_t tilesX = (width + kShadowTile - 1) / kShadowTile, tilesY = (height + kShadowTile - 1) / kShadowTile;
    std::vector<uint32_t> tileTerrain(size_t(tilesX) * tilesY, 0), tileOff(tileTerrain.size(), 0);
    size_t off = 0, acne = 0;
    double sum = 0.0;
    // Both views write the value in red and 1 in green on terrain.
    for (uint32_t y = 0; y < height; ++y)
        for (uint32_t x = 0; x < width; ++x) {
            const size_t i = (size_t(y) * width + x) * 4;
            if (i + 3 >= traced.rgba.size() || traced.rgba[i + 1] < 0.5f || mapped.rgba[i + 1] < 0.5f) continue;
            ++a.terrainPixels;
            const double d = std::abs(double(traced.rgba[i]) - double(mapped.rgba[i]));
            sum += d;
            const size_t t = size_t(y / kShadowTile) * tilesX + x / kShadowTile;
            ++tileTerrain[t];
            if (d > 0.5) ++off, ++tileOff[t];
            if (traced.rgba[i] >= 0.95f) {
                ++a.tracedLitPixels;
                if (mapped.rgba[i] < 0.9f) ++acne;
            }
        }
    if (a.tracedLitPixels > 0) a.acne = double(acne) / double(a.tracedLitPixels);
    if (a.terrainPixels > 0) {
        a.disagreeing = double(off) / double(a.terrainPixels);
        a.meanAbsDifference = sum / double(a.terrainPixels);
    }
    for (size_t t = 0; t < tileTerrain.size(); ++t)
        if (tileTerrain[t] >= kShadowTile * kShadowTile / 4)
            a.tileDisagreeing.push_back(float(tileOff[t]) / float(tileTerrain[t]));
    return a;
}

}  // namespace terralux
