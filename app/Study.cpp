#include "Study.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <numeric>
#include <sstream>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include "AtomicFile.h"
#include "BakeJob.h"
#include "ReflectionProbeFile.h"
#include "ProjectRenderer.h"
#include "SceneLighting.h"
#include "ShaderMath.h"
#include "TerrainLoading.h"
#include "bake/AdaptivePlacement.h"
#include "bake/DiffuseBake.h"
#include "bake/ProbeDiagnostics.h"
#include "bake/ProbePlacement.h"
#include "bake/ReflectionBake.h"
#include "bake/SphereSampling.h"
#include "lpv/Lpv.h"
#include "scene/OrbitCamera.h"
#include "terrain/HorizonAO.h"

#ifndef TERRALUX_VERSION
#define TERRALUX_VERSION "0.0.0"
#endif

namespace terralux {

const char* studyMetricName(StudyMetric m) {
    switch (m) {
        case StudyMetric::Irradiance: return "irradiance";
        case StudyMetric::ErrorMapP95: return "error_map_p95";
        case StudyMetric::AmbientOcclusion: return "ambient_occlusion";
        case StudyMetric::Lpv: return "lpv";
        case StudyMetric::Reflection: return "reflection";
        case StudyMetric::Shadow: return "shadow";
    }
    return "irradiance";
}

const char* studyMetricMeaning(StudyMetric m) {
    switch (m) {
        case StudyMetric::Irradiance:
            return "relative irradiance error of the interpolated probes against the path-traced reference";
        case StudyMetric::ErrorMapP95:
            return "relative error of the map's p95 against a map twice as dense";
        case StudyMetric::AmbientOcclusion:
            return "absolute error of horizon AO against traced sky visibility";
        case StudyMetric::Lpv:
            return "relative error of the LPV against the traced one-bounce sun irradiance";
        case StudyMetric::Reflection:
            return "relative RMS of prefiltered reflection luminance against a reference cube twice as fine";
        case StudyMetric::Shadow:
            return "share of terrain pixels per screen tile where the shadow maps and the traced sun visibility "
                   "differ by more than half";
    }
    return "";
}

std::vector<size_t> paretoFront(const std::vector<double>& cost, const std::vector<double>& error) {
    std::vector<size_t> order;
    for (size_t i = 0; i < cost.size() && i < error.size(); ++i)
        if (std::isfinite(cost[i]) && std::isfinite(error[i]) && cost[i] > 0.0 && error[i] > 0.0) order.push_back(i);
    // By cost, then error: walking up the costs, a point is on the front when it errs strictly
    // less than everything cheaper or as cheap.
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        return cost[a] != cost[b] ? cost[a] < cost[b] : error[a] < error[b];
    });
    std::vector<size_t> front;
    double best = INFINITY;
    for (size_t i : order)
        if (error[i] < best) {
            front.push_back(i);
            best = error[i];
        }
    return front;
}

namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Peak resident memory: Linux keeps a high-water mark (VmHWM) that writing 5 to clear_refs resets
// (proc(5)), so each point measures its own peak. Zero where /proc does not offer it.
uint64_t statusBytes(const char* field) {
    std::ifstream in("/proc/self/status");
    std::string line;
    const std::string key = std::string(field) + ":";
    while (std::getline(in, line))
        if (line.rfind(key, 0) == 0) return uint64_t(std::strtoull(line.c_str() + key.size(), nullptr, 10)) * 1024u;
    return 0;
}
void resetPeakMemory() {
    std::ofstream out("/proc/self/clear_refs");
    if (out) out << "5";
}

constexpr uint64_t kStudySeed = 0x57D1E5ull;
constexpr int kPointsPerSide = 16;          // study points: up to 16 x 16 over the ground
constexpr size_t kMinPoints = 36;
constexpr int kAoRays = 512;
constexpr int kAoVertices = 512;
constexpr int kLpvPoints = 256;
constexpr int kLpvRays = 512;
// Reflection truth: per probe, a cube twice as fine a side as the finest swept or set, with 4 rays
// a texel, read at the roughnesses the bake's own comparison uses (kReflectionErrorRoughness).
constexpr int kReflectionSweep[] = {8, 16, 32};
constexpr int kReflectionReferenceRays = 4;
constexpr double kSafety = 1.25;            // estimates are scaled up by this before they are trusted
// Shadows: frames of this size from the project's camera; the first shadow setting also starts
// the Vulkan device, uploads the terrain and traces the sun at its vertices, which this many
// seconds cover on a 2-core CPU rasteriser.
constexpr uint32_t kShadowWidth = 960, kShadowHeight = 540;
constexpr double kShadowSetupSeconds = 4.0;

std::string fmt(const char* f, double v) {
    char b[64];
    std::snprintf(b, sizeof b, f, v);
    return b;
}

// The peak resident memory a setting adds: started before it, read after.
struct PeakMemory {
    uint64_t before = statusBytes("VmRSS");
    PeakMemory() { resetPeakMemory(); }
    uint64_t added() const {
        const uint64_t peak = statusBytes("VmHWM");
        return peak > before ? peak - before : 0;
    }
};

void setErrors(StudyPoint& p, std::vector<float> errors) {
    p.points = errors.size();
    const Spread s = spreadOf(std::move(errors));
    p.errorMean = s.mean, p.errorP95 = s.p95, p.errorMax = s.max;
}

// A setting to try: its overrides, and how to measure it.
struct Candidate {
    std::string knob, label;
    std::vector<std::string> sets;
    StudyMetric metric = StudyMetric::Irradiance;
    int param = 0;            // error-map resolution, AO directions
    double work = 0.0;        // in the knob's own unit (rays, vertex-directions, cascades)
    double estimate = 0.0;    // seconds
};

// A point's settings as they apply to the user's project, not to the resolved one the study
// measures. Where the project asks for an accuracy (bake.target_error, a volume's target_error),
// a point that sets what the target chooses clears that target and pins the rest of the target's
// choice, so that the applied project bakes what was measured.
std::vector<std::string> pinTargets(std::vector<std::string> sets, const Project& original, const Project& resolved,
                                    size_t volumeIndex) {
    auto keyOf = [](const std::string& set) { return set.substr(0, set.find('=')); };
    auto sets_ = [&](const std::string& key) {
        return std::any_of(sets.begin(), sets.end(), [&](const std::string& x) { return keyOf(x) == key; });
    };
    auto touches = [&](const std::vector<std::string>& keys) {
        return std::any_of(keys.begin(), keys.end(), [&](const std::string& k) {
            return std::any_of(sets.begin(), sets.end(), [&](const std::string& x) { return keyOf(x).rfind(k, 0) == 0; });
        });
    };
    std::vector<std::string> pins;
    const BakeSettings& rb = resolved.scene.bake;
    if (original.scene.bake.targetError && touches({"bake.rays", "bake.bounces", "bake.quality"})) {
        pins.push_back("bake.target_error=null");
        if (!sets_("bake.rays") && rb.rays) pins.push_back("bake.rays=" + std::to_string(*rb.rays));
        if (!sets_("bake.bounces") && rb.bounces) pins.push_back("bake.bounces=" + std::to_string(*rb.bounces));
    }
    const std::string at = "probe_volumes[" + std::to_string(volumeIndex) + "].";
    if (volumeIndex < original.scene.probeVolumes.size() && original.scene.probeVolumes[volumeIndex].targetError &&
        touches({at + "grid_dims", at + "placement", at + "spacing", at + "adaptive."})) {
        const ProbeVolumeSettings& rv = resolved.scene.probeVolumes[volumeIndex];
        pins.push_back(at + "target_error=null");
        if (!sets_(at + "grid_dims"))
            pins.push_back(at + "grid_dims=" + std::to_string(rv.gridDims[0]) + "," + std::to_string(rv.gridDims[2]));
        if (!sets_(at + "adaptive.tolerance") && rv.adaptive.tolerance)
            pins.push_back(at + "adaptive.tolerance=" + fmt("%.6g", *rv.adaptive.tolerance));
    }
    sets.insert(sets.end(), pins.begin(), pins.end());
    return sets;
}

struct Study {
    const Project& project;
    const StudyOptions& options;
    const StudyProgress& progress;
    const std::atomic<bool>* cancel;
    Clock::time_point start = Clock::now();
    StudyResult result;

    DemImportResult terrain;
    BakeLighting lighting;
    std::unique_ptr<HeightfieldTracer> tracer;
    size_t volumeIndex = 0;
    std::vector<glm::vec3> points;      // study points above the ground
    std::vector<sh::ShRgb> reference;   // path-traced at each point

    // Seconds per unit of work, per kind, from the largest piece of work of that kind measured so
    // far: small settings are dominated by fixed costs (placement, threads starting) that would
    // make every larger setting look dearer than it is. Settings run cheapest first, so the rate
    // follows the sizes about to be estimated.
    std::map<std::string, double> rate;
    std::map<std::string, double> rateWork;
    void learn(const std::string& kind, double work, double seconds) {
        if (work <= 0.0 || (rateWork.count(kind) && work < rateWork[kind])) return;
        rateWork[kind] = work;
        rate[kind] = seconds / work;
    }

    // The project as the user has it: `project` is its resolution (resolveTargets), what the
    // study measures, which differs where it asks for an accuracy.
    const Project* original = nullptr;

    Study(const Project& p, const StudyOptions& o, const StudyProgress& pr, const std::atomic<bool>* c)
        : project(p), options(o), progress(pr), cancel(c) {}

    const Heightfield& hf() const { return terrain.heightfield; }
    double elapsed() const { return secondsSince(start); }
    double left() const { return options.budgetSeconds - elapsed(); }
    bool cancelled() const { return cancel && cancel->load(); }
    void report(const std::string& phase) {
        if (progress) progress(phase, std::clamp(elapsed() / options.budgetSeconds, 0.0, 1.0));
    }
    BakeControl control() const { return BakeControl{{}, cancel}; }

    SceneDescription sceneWith(const std::vector<std::string>& sets) const {
        nlohmann::json doc = projectToJson(project);
        for (const auto& s : sets) applyOverride(doc, s);
        return sceneFromJson(doc, "study", nullptr);
    }
    const ProbeVolumeSettings& volumeOf(const SceneDescription& s) const { return s.probeVolumes[volumeIndex]; }
    std::string volumePath() const { return "probe_volumes[" + std::to_string(volumeIndex) + "]."; }

    void prepare();
    void placePoints();
    void bakeReference();
    std::vector<Candidate> candidates(const ProbeLayout& currentLayout);
    double expectedRays(const ProbeRays& r) const;
    double estimate(const Candidate& c) const;
    StudyPoint measureProbes(const Candidate& c);
    StudyPoint measureErrorMap(const Candidate& c);
    StudyPoint measureAo(const Candidate& c);
    StudyPoint measureLpv(const Candidate& c);
    StudyPoint measureReflection(const Candidate& c);
    StudyPoint measureShadow(const Candidate& c);
    StudyPoint measure(const Candidate& c);
    void run();

    // Kept from the current point for the error-map knob.
    struct Baked {
        ProbeLayout layout;
        std::vector<sh::ShRgb> sh;
        std::unique_ptr<IrradianceCache> cache;
        BakeQuality q;
        ProbeRays rays;
        double meanRays = 0.0;  // per valid probe, as traced
    };
    std::unique_ptr<Baked> current;
    std::optional<ErrorMapStats> denseMap;  // the error-map knob's truth
    int denseMapResolution = 0;
    // AO truth.
    std::vector<std::pair<int, int>> aoVertices;
    std::vector<float> aoTruth;
    std::unique_ptr<HeightfieldTracer> footprintTracer;
    // LPV truth.
    std::vector<glm::vec3> lpvP, lpvN;
    std::vector<float> lpvTruth;
    float lpvFloor = 0.0f;
    // Reflection truth: the project's layout, the cache its rays read, per probe and roughness the
    // reference luminance over the 256 error directions.
    std::unique_ptr<IrradianceCache> reflectionCache;
    std::optional<ReflectionLighting> reflectionLight;
    ReflectionLayout reflectionLayout;
    std::vector<std::vector<double>> reflectionTruth;
    int reflectionReferenceSize = 0;
    // Shadows: the device and the renderer, made for the first shadow setting; why not, when the
    // device could not be had.
    std::unique_ptr<vk::VulkanContext> vulkan;
    std::unique_ptr<ProjectRenderer> shadowRenderer;
    std::string shadowsUnavailable;
    // No device, or one that failed: the bake's knobs are still studied; the shadows are not, and
    // the outputs say why.
    void shadowsWithout(const std::string& why) {
        shadowsUnavailable = why;
        shadowRenderer.reset();
        vulkan.reset();
        result.notStudied.push_back("shadows: " + why + "; the shadow maps are measured on a Vulkan device (--device)");
    }
};

void Study::prepare() {
    report("loading terrain");
    terrain = loadProjectTerrain(project);
    BakeScene traced = bakeSceneOf(project, hf());
    lighting = traced.lighting;
    tracer = std::move(traced.tracer);
    const auto& vols = project.scene.probeVolumes;
    auto it = std::find_if(vols.begin(), vols.end(), [](const ProbeVolumeSettings& v) { return v.enabled; });
    if (it == vols.end())
        throw ProjectError("probe_volumes: no enabled volume; the study varies the first enabled one");
    volumeIndex = size_t(it - vols.begin());
    result.volume = it->name;
    result.terrain = terrain.source.path;
    result.project = project.file.empty() ? std::string() : project.file.filename().string();
}

// The study points: the centres of a grid of up to kPointsPerSide² cells over the volume's
// footprint on the terrain, at the height its error map measures, where a probe covers them.
void Study::placePoints() {
    const ProbeVolumeSettings& v = volumeOf(project.scene);
    const ProbeLayout layout = placeProbes(v, hf());
    const float height = errorMapHeight(v, layout);
    const ErrorMap grid = errorMapGrid(layout, hf(), kPointsPerSide, height);
    for (uint32_t j = 0; j < grid.nz; ++j)
        for (uint32_t i = 0; i < grid.nx; ++i) {
            const float x = grid.x0 + float(i) * grid.step, z = grid.z0 + float(j) * grid.step;
            if (!hf().contains(x, z)) continue;
            points.emplace_back(x, hf().surfaceHeight(x, z) + height, z);
        }
    result.reference.height = height;
}

void Study::bakeReference() {
    report("reference");
    int rays = qualityPreset(QualityPreset::Reference).rays;
    // Calibrate on a few points, then keep at most a fifth of the budget for the reference:
    // fewer points first, then fewer rays (never below 1024: the reference must stay far below
    // the errors it judges).
    const size_t probe = std::min<size_t>(8, points.size());
    std::vector<glm::vec3> few(points.begin(), points.begin() + long(probe));
    const auto t0 = Clock::now();
    referenceProbes(lighting, kMaxBounces, few, std::vector<uint8_t>(few.size(), 1), rays, kStudySeed, control());
    const double perPoint = secondsSince(t0) / double(std::max<size_t>(probe, 1));
    const double allowed = 0.2 * options.budgetSeconds;
    size_t n = points.size();
    while (n > kMinPoints && double(n) * perPoint > allowed) n = std::max(kMinPoints, n * 3 / 4);
    while (rays > 1024 && double(n) * perPoint * rays / qualityPreset(QualityPreset::Reference).rays > allowed) rays /= 2;
    if (n < points.size()) {
        // Every k-th point, so the thinned set still spans the footprint.
        std::vector<glm::vec3> kept;
        const double stride = double(points.size()) / double(n);
        for (size_t k = 0; k < n; ++k) kept.push_back(points[size_t(double(k) * stride)]);
        points = std::move(kept);
    }
    const auto t1 = Clock::now();
    reference = referenceProbes(lighting, kMaxBounces, points, std::vector<uint8_t>(points.size(), 1), rays,
                                kStudySeed ^ 0xF00Dull, control()).sh;
    result.reference.points = points.size();
    result.reference.raysPerPoint = rays;
    result.reference.seconds = secondsSince(t1);
}

// The sweeps: each knob over its useful range with everything else as the project has it. The
// project's own value is the current point, so it is not repeated in its knob.
// Rays a probe is expected to trace under `r`, for the estimates: a fixed count, or a target's
// first round times the growth the current bake measured on this terrain (1 before any bake).
double Study::expectedRays(const ProbeRays& r) const {
    // The traced rays count a sampled glow's (probeRaysWithGlow), and so does meanRays.
    const bool glow = probesSampleGlow(lighting);
    if (!r.adaptive()) return probeRaysWithGlow(double(r.rays), glow);
    const double growth =
        current && current->rays.adaptive() && current->meanRays > 0 ? current->meanRays / current->rays.rays : 1.0;
    return std::min(probeRaysWithGlow(double(r.maxRays), glow), double(r.rays) * growth);
}

std::vector<Candidate> Study::candidates(const ProbeLayout& cur) {
    const SceneDescription& s = project.scene;
    const ProbeVolumeSettings& v = volumeOf(s);
    const BakeQuality q = qualityOf(s.bake);
    std::vector<Candidate> out;
    auto add = [&](std::string knob, std::string label, std::vector<std::string> sets, StudyMetric m = StudyMetric::Irradiance,
                   int param = 0) {
        Candidate c;
        c.knob = std::move(knob);
        c.label = std::move(label);
        c.sets = std::move(sets);
        c.metric = m;
        c.param = param;
        out.push_back(std::move(c));
    };
    for (QualityPreset p : {QualityPreset::Draft, QualityPreset::Standard, QualityPreset::High})
        if (p != s.bake.quality || s.bake.rays || s.bake.bounces)
            add("quality", qualityName(p),
                {std::string("bake.quality=") + qualityName(p), "bake.rays=null", "bake.bounces=null"});
    const ProbeRays volume = volumeRays(q, v);
    for (int r : {16, 32, 64, 128, 256, 512, 1024, 2048})
        if (volume.adaptive() || r != volume.rays)
            add("rays", "rays " + std::to_string(r),
                {v.rayCount ? volumePath() + "ray_count=" + std::to_string(r) : "bake.rays=" + std::to_string(r)});
    for (int b = 0; b <= 4; ++b)
        if (b != q.bounces) add("bounces", "bounces " + std::to_string(b), {"bake.bounces=" + std::to_string(b)});

    if (refinedByError(v.placement)) {
        for (double t : {0.2, 0.1, 0.05, 0.02, 0.01})
            if (!v.adaptive.tolerance || std::abs(*v.adaptive.tolerance - t) > 1e-9)
                add("tolerance", "tolerance " + fmt("%g", t), {volumePath() + "adaptive.tolerance=" + fmt("%g", t)});
    } else {
        // Probe counts over the same footprint: the spacing shrinks as the count per side grows.
        const bool terrainGrid = v.placement == ProbePlacement::Terrain;
        const int ax = cur.probeDims[0], az = cur.probeDims[2];
        const double aspect = double(az) / double(std::max(ax, 1));
        const int cap = terrainGrid ? kMaxTerrainGridProbes : kMaxBoxGridProbes;
        for (int n : {4, 6, 8, 12, 16, 24, 32, 48, 64}) {
            const int nx = n, nz = std::max(1, int(std::lround(n * aspect)));
            if ((nx == ax && nz == az) || nx * nz * (terrainGrid ? 1 : cur.probeDims[1]) > cap) continue;
            std::vector<std::string> sets;
            if (terrainGrid) {
                sets.push_back(volumePath() + "grid_dims=" + std::to_string(nx) + "," + std::to_string(nz));
                if (v.spacing) {
                    const double ex = double(cur.spacing.x) * (ax - 1), ez = double(cur.spacing.z) * (az - 1);
                    sets.push_back(volumePath() + "spacing=" + fmt("%.6g", ex / std::max(nx - 1, 1)) + "," +
                                   fmt("%.6g", ez / std::max(nz - 1, 1)));
                }
                const double spacing = double(std::max(cur.spacing.x * float(ax - 1) / float(std::max(nx - 1, 1)), 0.0f));
                add("spacing", std::to_string(nx) + "x" + std::to_string(nz) + " (" + fmt("%.0f", spacing) + " m)", sets);
            } else {
                const int ny = cur.probeDims[1];
                sets.push_back(volumePath() + "grid_dims=" + std::to_string(nx) + "," + std::to_string(ny) + "," +
                               std::to_string(nz));
                if (v.spacing) continue;  // a box with a fixed cube edge cannot keep its footprint
                add("spacing", std::to_string(nx) + "x" + std::to_string(ny) + "x" + std::to_string(nz), sets);
            }
        }
    }

    // Spacing and sampling together: the densest placements with a cheaper and a dearer preset,
    // so the front can show where fewer rays on more probes beat more rays on fewer. The
    // candidates are the costliest, so they run last, with what the budget has left.
    {
        std::vector<Candidate> placements;
        for (const Candidate& c : out)
            if (c.knob == "spacing" || c.knob == "tolerance") placements.push_back(c);
        const size_t keep = std::min<size_t>(placements.size(), 4);
        for (size_t k = placements.size() - keep; k < placements.size(); ++k)
            for (QualityPreset p : {QualityPreset::Draft, QualityPreset::High})
                if (p != s.bake.quality || s.bake.rays || s.bake.bounces) {
                    std::vector<std::string> sets = placements[k].sets;
                    sets.insert(sets.end(), {std::string("bake.quality=") + qualityName(p), "bake.rays=null",
                                             "bake.bounces=null"});
                    add("placement_quality", placements[k].label + ", " + qualityName(p), sets);
                }
    }

    for (int r : {8, 16, 32, 64, 128})
        if (r < denseMapResolution) add("error_map", "error map " + std::to_string(r), {"bake.error_map_resolution=" + std::to_string(r)},
                                        StudyMetric::ErrorMapP95, r);

    if (s.ao.enabled)
        for (int d : {8, 16, 32, 64})
            if (d != s.ao.directions)
                add("ao_directions", "AO " + std::to_string(d) + " directions", {"ao.directions=" + std::to_string(d)},
                    StudyMetric::AmbientOcclusion, d);
    if (s.lpv.enabled) {
        for (int ql = 0; ql <= 2; ++ql)
            if (ql != s.lpv.quality)
                add("lpv_quality", "LPV quality " + std::to_string(ql), {"lpv.quality=" + std::to_string(ql)},
                    StudyMetric::Lpv);
        for (int c = 1; c <= 4; ++c)
            if (c != s.lpv.cascades)
                add("lpv_cascades", "LPV " + std::to_string(c) + " cascades", {"lpv.cascades=" + std::to_string(c)},
                    StudyMetric::Lpv);
    }
    if (s.reflectionProbes.enabled) {
        const ReflectionProbeSettings& r = s.reflectionProbes;
        const std::string enc = reflectionEncodingName(r.encoding);
        add("reflection_resolution", "reflection " + std::to_string(r.resolution) + "² " + enc + " (current)",
            {"reflection_probes.resolution=" + std::to_string(r.resolution)}, StudyMetric::Reflection);
        for (int res : kReflectionSweep)
            if (res != r.resolution)
                add("reflection_resolution", "reflection " + std::to_string(res) + "² " + enc,
                    {"reflection_probes.resolution=" + std::to_string(res)}, StudyMetric::Reflection);
        for (int rays : {2, 4, 16, 64})
            if (rays != r.rayCount)
                add("reflection_rays", "reflection " + std::to_string(rays) + " rays/texel",
                    {"reflection_probes.ray_count=" + std::to_string(rays)}, StudyMetric::Reflection);
        const std::string other = reflectionEncodingName(r.encoding == ReflectionEncoding::Cubemap ? ReflectionEncoding::Faces
                                                                                                  : ReflectionEncoding::Cubemap);
        add("reflection_encoding", "reflection " + other, {"reflection_probes.encoding=" + other}, StudyMetric::Reflection);
    }
    // The renderer draws no shadow maps once the sun is more than about 3° below the horizon.
    const bool imageSun = sunFromSkyImage(s);
    const std::optional<ImageSun> fromImage = imageSun ? std::optional(imageSunOf(lightingOf(project, hf()))) : std::nullopt;
    const double sunElevation = fromImage ? fromImage->elevationDeg : sunAnglesOf(s, hf()).elevationDeg;
    const bool sunlit = !fromImage || fromImage->illuminanceLux > 0.0;
    const bool sunUp = sunlit && std::sin(glm::radians(sunElevation)) > -0.05;
    if (s.shadows.enabled && !sunlit)
        result.notStudied.push_back("shadows: the sky image has no sun to cast them (sun.follow_sky)");
    else if (s.shadows.enabled && !sunUp)
        result.notStudied.push_back(
            "shadows: the sun is below the horizon (" +
            (imageSun ? "the sky image's sun stands at " + fmt("%.1f", sunElevation) + "°"
             : s.sun.mode == SunMode::Manual ? "sun.elevation_deg = " + fmt("%g", sunElevation)
                                             : "sun.date and sun.time_h put it at " + fmt("%.1f", sunElevation) + "°") +
            "), so no shadow maps are drawn");
    if (s.shadows.enabled && sunUp) {
        const ShadowSettings& sh = s.shadows;
        const std::string filter = shadowFilterName(sh.filter);
        const std::string res = std::to_string(sh.mapResolution) + "²";
        auto shadowLabel = [&](int cascades, const std::string& map, const std::string& f) {
            return "shadows " + std::to_string(cascades) + " x " + map + " " + f;
        };
        add("shadow_cascades", shadowLabel(sh.cascades, res, filter) + " (current)",
            {"shadows.cascades=" + std::to_string(sh.cascades)}, StudyMetric::Shadow);
        for (int n = 1; n <= 4; ++n)
            if (n != sh.cascades) {
                // Manual splits are one fewer than the cascades: another count takes the practical scheme.
                std::vector<std::string> sets{"shadows.cascades=" + std::to_string(n)};
                if (sh.splitMode == SplitMode::Manual) sets.insert(sets.end(), {"shadows.split_mode=practical", "shadows.splits=null"});
                add("shadow_cascades", shadowLabel(n, res, filter), sets, StudyMetric::Shadow);
            }
        for (int m : {1024, 2048, 4096})
            if (m != sh.mapResolution)
                add("shadow_resolution", shadowLabel(sh.cascades, std::to_string(m) + "²", filter),
                    {"shadows.map_resolution=" + std::to_string(m)}, StudyMetric::Shadow);
        for (ShadowFilter f : {ShadowFilter::Hard, ShadowFilter::Pcf, ShadowFilter::Pcss})
            if (f != sh.filter)
                add("shadow_filter", shadowLabel(sh.cascades, res, shadowFilterName(f)),
                    {std::string("shadows.filter=") + shadowFilterName(f)}, StudyMetric::Shadow);
        // The terrain's horizon map against the maps alone (or the other way round).
        add("shadow_heightfield", shadowLabel(sh.cascades, res, filter) + (sh.heightfield ? ", maps only" : ", terrain horizon"),
            {std::string("shadows.heightfield=") + (sh.heightfield ? "false" : "true")}, StudyMetric::Shadow);
    }

    // Work, in each kind's unit, for the estimates.
    for (Candidate& c : out) {
        const SceneDescription cs = sceneWith(c.sets);
        switch (c.metric) {
            case StudyMetric::Irradiance: {
                const ProbeVolumeSettings& cv = volumeOf(cs);
                const BakeQuality cq = qualityOf(cs.bake);
                const double rays = expectedRays(volumeRays(cq, cv));
                double probes;
                if (refinedByError(cv.placement)) {
                    // The refinement bakes each tested leaf's children (8 octants, 4 quadrants): up to
                    // about three times the geometric tree's probes at the tolerances swept.
                    probes = 3.0 * double(cur.validCount());
                } else {
                    probes = double(placeProbes(cv, hf()).validCount());
                }
                const uint64_t probeRays = uint64_t(probes * rays);
                double cacheRays = 0.0;
                if (cq.bounces > 0) {
                    const auto pts = IrradianceCache::gridPoints(hf(), cacheResolutionFor(hf(), cq, probeRays));
                    cacheRays = double(pts[0]) * pts[1] * cq.cacheRays * (1.0 + 0.25 * cq.bounces);
                }
                c.work = double(probeRays) + cacheRays;
                break;
            }
            case StudyMetric::ErrorMapP95:
                c.work = double(c.param) * c.param * (current ? current->meanRays : expectedRays(volumeRays(q, v)));
                break;
            case StudyMetric::AmbientOcclusion: c.work = double(hf().width()) * hf().depth() * c.param; break;
            case StudyMetric::Lpv: c.work = double(cs.lpv.cascades) * (cs.lpv.quality == 2 ? 1.3 : 1.0); break;
            case StudyMetric::Reflection: {
                // Traced texels; a faces set is baked as a cube too.
                const ReflectionProbeSettings& r = cs.reflectionProbes;
                c.work = double(r.gridDims[0]) * r.gridDims[1] * 6.0 * r.resolution * r.resolution * r.rayCount;
                break;
            }
            case StudyMetric::Shadow:
                // The maps' texels drawn, and the frame's pixels (a map texel costs about a pixel).
                c.work = double(cs.shadows.cascades) * cs.shadows.mapResolution * cs.shadows.mapResolution +
                         double(kShadowWidth) * kShadowHeight;
                break;
        }
    }
    return out;
}

const char* rateKey(StudyMetric m) {
    switch (m) {
        case StudyMetric::Irradiance:
        case StudyMetric::ErrorMapP95: return "rays";
        case StudyMetric::AmbientOcclusion: return "ao";
        case StudyMetric::Lpv: return "lpv";
        case StudyMetric::Reflection: return "reflection";
        case StudyMetric::Shadow: return "shadow";
    }
    return "rays";
}

double Study::estimate(const Candidate& c) const {
    auto it = rate.find(rateKey(c.metric));
    if (it == rate.end() && c.metric == StudyMetric::Shadow && !shadowRenderer) return kShadowSetupSeconds;
    if (it == rate.end()) return -1.0;  // nothing of its kind ran yet
    return kSafety * c.work * it->second;
}

// A bake of the candidate's probes read at the study points.
StudyPoint Study::measureProbes(const Candidate& c) {
    const SceneDescription s = sceneWith(c.sets);
    const ProbeVolumeSettings& v = volumeOf(s);
    const BakeQuality q = qualityOf(s.bake);
    const ProbeRays rays = volumeRays(q, v);
    StudyPoint p;
    const PeakMemory memory;
    const auto t0 = Clock::now();
    auto baked = std::make_unique<Baked>();
    baked->q = q;
    baked->rays = rays;
    ProbeLayout layout = placeProbes(v, hf());
    uint64_t traced = 0;
    if (q.bounces > 0) {
        uint64_t planned = uint64_t(layout.validCount()) * uint64_t(rays.planned());
        if (refinedByError(v.placement)) planned *= 3;
        baked->cache = std::make_unique<IrradianceCache>(lighting, cacheResolutionFor(hf(), q, planned), q.cacheRays,
                                                         q.sunSamples, q.bounces - 1, control());
        traced += baked->cache->rays();
    }
    ProbeBake bake;
    if (refinedByError(v.placement)) {
        const ProbeBaker baker = seededBaker(lighting, baked->cache.get(), q.bounces, rays, kStudySeed, control());
        AdaptiveBake a = bakeAdaptive(v, hf(), baker);
        layout = std::move(a.layout);
        bake = std::move(a.bake);
    } else {
        bake = bakeProbes(lighting, baked->cache.get(), q.bounces, layout.positions, layout.valid, rays, kStudySeed,
                          control());
    }
    traced += bake.rays;
    baked->meanRays = raySpreadOf(bake, layout.valid).mean;
    if (s.bake.deringing) sh::deringProbes(bake.sh, layout.valid);
    p.seconds = secondsSince(t0);
    p.peakMemoryBytes = memory.added();
    p.outputBytes = layout.fileBytes();
    p.probes = layout.validCount();

    std::vector<float> err(points.size(), NAN);
    const double floor = interpolationErrorFloor(reference);
    tbb::parallel_for(size_t(0), points.size(), [&](size_t k) {
        sh::ShRgb at;
        if (interpolateProbes(layout, bake.sh, points[k], at))
            err[k] = relativeIrradianceError(at, reference[k], floor);
    });
    std::vector<float> covered;
    for (float e : err)
        if (std::isfinite(e)) covered.push_back(e);
    setErrors(p, std::move(covered));
    learn("rays", double(traced), p.seconds);
    if (c.knob == "current") {
        baked->layout = std::move(layout);
        baked->sh = std::move(bake.sh);
        current = std::move(baked);
    }
    return p;
}

ErrorMapStats mapStats(const Study& st, int resolution, uint64_t* rays) {
    const Study::Baked& b = *st.current;
    const ProbeBaker counted = deringedBaker(
        seededBaker(st.lighting, b.cache.get(), b.q.bounces, b.rays, kStudySeed, st.control()),
        st.project.scene.bake.deringing, rays);
    const ProbeVolumeSettings& v = st.volumeOf(st.project.scene);
    return errorMapStats(measureErrorMap(b.layout, b.sh, st.hf(), counted, resolution,
                                         errorMapHeight(v, b.layout), kStudySeed));
}

StudyPoint Study::measureErrorMap(const Candidate& c) {
    StudyPoint p;
    const PeakMemory memory;
    const auto t0 = Clock::now();
    uint64_t rays = 0;
    const ErrorMapStats m = mapStats(*this, c.param, &rays);
    p.seconds = secondsSince(t0);
    p.peakMemoryBytes = memory.added();
    p.points = m.points;
    p.probes = current->layout.validCount();
    p.outputBytes = current->layout.fileBytes();
    const double e = denseMap->p95 > 0.0 ? std::abs(m.p95 - denseMap->p95) / denseMap->p95 : 0.0;
    p.errorMean = p.errorP95 = p.errorMax = e;
    return p;
}

StudyPoint Study::measureAo(const Candidate& c) {
    if (aoTruth.empty()) {
        // Vertices away from the border by a tenth of the footprint, where the horizon search
        // sees terrain on every side; truth traced with the skirt off, as horizon AO sees it.
        footprintTracer = std::make_unique<HeightfieldTracer>(hf(), HeightfieldTracer::Options{false});
        const int mx = std::max(1, hf().width() / 10), mz = std::max(1, hf().depth() / 10);
        Rng rng(kStudySeed ^ 0xA0);
        for (int i = 0; i < kAoVertices; ++i) {
            const int col = std::min(hf().width() - 1, mx + int(rng.next() * float(std::max(1, hf().width() - 2 * mx))));
            const int row = std::min(hf().depth() - 1, mz + int(rng.next() * float(std::max(1, hf().depth() - 2 * mz))));
            aoVertices.emplace_back(col, row);
        }
        aoTruth.resize(aoVertices.size());
        tbb::parallel_for(size_t(0), aoVertices.size(), [&](size_t i) {
            const auto [col, row] = aoVertices[i];
            aoTruth[i] = tracedSkyVisibility(*footprintTracer, hf().vertex(col, row), hf().vertexNormal(col, row),
                                             kAoRays, kStudySeed + i);
        });
    }
    StudyPoint p;
    p.metric = StudyMetric::AmbientOcclusion;
    HorizonAoSettings settings;
    settings.directions = c.param;
    settings.maxDistance = project.scene.ao.maxDistance.value_or(0.0);
    const PeakMemory memory;
    const auto t0 = Clock::now();
    const std::vector<float> field = horizonSkyVisibility(hf(), settings, [&](double) { return !cancelled(); });
    if (field.empty()) throw BakeCancelled();
    p.seconds = secondsSince(t0);
    p.peakMemoryBytes = memory.added();
    std::vector<float> err;
    for (size_t i = 0; i < aoVertices.size(); ++i) {
        const auto [col, row] = aoVertices[i];
        err.push_back(std::abs(field[size_t(row) * size_t(hf().width()) + size_t(col)] - aoTruth[i]));
    }
    setErrors(p, std::move(err));
    learn("ao", c.work, p.seconds);
    return p;
}

StudyPoint Study::measureLpv(const Candidate& c) {
    const SceneDescription s = sceneWith(c.sets);
    const OrbitCamera camera = OrbitCamera::fromSettings(s.camera, hf());
    const glm::dvec3 eye(camera.lpvEye()), view(camera.lpvViewDirection());
    if (lpvTruth.empty()) {
        // Ground points inside the finest cascade of the project's own settings, less its fade:
        // where every cascade count and quality is read.
        const lpv::CascadeLayout c0 = lpv::placeCascades(lpv::resolvedOn(project.scene.lpv, hf()), eye, view).front();
        const glm::dvec3 lo = c0.origin() + glm::dvec3(project.scene.lpv.fadeRange * c0.cellSize);
        const double span = c0.size - 2.0 * project.scene.lpv.fadeRange * c0.cellSize;
        Rng rng(kStudySeed ^ 0x1F);
        for (int tries = 0; int(lpvP.size()) < kLpvPoints && tries < 100 * kLpvPoints; ++tries) {
            const float x = float(lo.x + span * rng.next()), z = float(lo.z + span * rng.next());
            if (!hf().contains(x, z)) continue;
            lpvP.emplace_back(x, hf().surfaceHeight(x, z), z);
            lpvN.push_back(hf().surfaceNormal(x, z));
        }
        lpvTruth.resize(lpvP.size());
        tbb::parallel_for(size_t(0), lpvP.size(), [&](size_t i) {
            lpvTruth[i] = glsl::rec709Luminance(sunFirstBounce(lighting, lpvP[i], lpvN[i], kLpvRays, kStudySeed + 7919u * i));
        });
        double mean = 0.0;
        for (float t : lpvTruth) mean += t;
        // The floor keeps points the bounce barely reaches from dominating (as the LPV benchmark).
        lpvFloor = float(0.05 * mean / double(std::max<size_t>(lpvTruth.size(), 1)));
    }
    StudyPoint p;
    p.metric = StudyMetric::Lpv;
    const PeakMemory memory;
    const auto t0 = Clock::now();
    const lpv::Volumes volumes(lpv::resolvedOn(s.lpv, hf()), {&lighting, &s.lights}, eye, view);
    p.seconds = secondsSince(t0);
    p.peakMemoryBytes = memory.added();
    std::vector<float> err;
    for (size_t i = 0; i < lpvP.size(); ++i) {
        const glm::vec3 toEye = glm::normalize(glm::vec3(eye) - lpvP[i]);
        const float value = glsl::rec709Luminance(volumes.evaluate(lpvP[i], lpvN[i], toEye).irradiance);
        err.push_back(std::abs(value - lpvTruth[i]) / std::max(lpvTruth[i], std::max(lpvFloor, 1e-12f)));
    }
    setErrors(p, std::move(err));
    learn("lpv", c.work, p.seconds);
    return p;
}

StudyPoint Study::measureReflection(const Candidate& c) {
    const SceneDescription s = sceneWith(c.sets);
    if (!reflectionLight) {
        // The light the bake's own reflection pass reads when it has no probes' cache.
        const ReflectionProbeSettings& r = project.scene.reflectionProbes;
        reflectionLight = reflectionLightingOf(lighting, qualityOf(project.scene.bake), r.groundColor, nullptr, 0,
                                               reflectionCache, control());
        reflectionLayout = placeReflectionProbes(r, hf());
        reflectionReferenceSize = 2 * std::max(kReflectionSweep[std::size(kReflectionSweep) - 1], r.resolution);
        const size_t n = reflectionLayout.count(), nr = kReflectionErrorRoughness.size();
        reflectionTruth.assign(n * nr, {});
        tbb::parallel_for(size_t(0), n, [&](size_t i) {
            if (cancelled()) return;
            const RadianceCube ref = traceRadianceCube(*reflectionLight, reflectionLayout.positions[i],
                                                       reflectionReferenceSize, kReflectionReferenceRays,
                                                       splitmix64(kStudySeed ^ 0x2EF) + i);
            for (size_t k = 0; k < nr; ++k) reflectionTruth[i * nr + k] = referenceLuminance(ref, kReflectionErrorRoughness[k]);
        });
        if (cancelled()) throw BakeCancelled();
    }
    StudyPoint p;
    p.metric = StudyMetric::Reflection;
    const PeakMemory memory;
    const auto t0 = Clock::now();
    ReflectionProbeSet set = bakeReflectionProbes(*reflectionLight, s.reflectionProbes, reflectionLayout, kStudySeed,
                                                  control());
    toEncoding(set, s.reflectionProbes.encoding);
    p.seconds = secondsSince(t0);
    p.peakMemoryBytes = memory.added();
    p.outputBytes = encodeReflectionProbes(set).size();
    p.probes = set.probes.size();
    std::vector<float> err;
    const size_t nr = kReflectionErrorRoughness.size();
    for (size_t i = 0; i < set.probes.size(); ++i)
        for (size_t k = 0; k < nr; ++k)
            err.push_back(reflectionProbeError(set, i, set.encoding, reflectionTruth[i * nr + k], kReflectionErrorRoughness[k]));
    setErrors(p, std::move(err));
    learn("reflection", c.work, p.seconds);
    const ReflectionProbeSettings& own = project.scene.reflectionProbes;
    p.current = s.reflectionProbes.resolution == own.resolution && s.reflectionProbes.rayCount == own.rayCount &&
                s.reflectionProbes.encoding == own.encoding;
    return p;
}

// Where the shadow maps of the candidate's settings disagree with the sun's visibility traced at
// the terrain's vertices, from the project's camera (measureShadowAgreement), and what the frame
// that draws the maps costs.
StudyPoint Study::measureShadow(const Candidate& c) {
    const SceneDescription s = sceneWith(c.sets);
    if (!shadowRenderer) {
        vk::ContextOptions o;
        o.device = options.device;
        vulkan = std::make_unique<vk::VulkanContext>(o);
        // The terrain as the study imported it; no horizon AO, which no shadow view reads.
        shadowRenderer = std::make_unique<ProjectRenderer>(*vulkan, project, terrain, false);
    }
    const auto t0 = Clock::now();
    Project candidate = project;
    candidate.scene = s;
    shadowRenderer->setProject(candidate);
    const ShadowAgreement a = measureShadowAgreement(*shadowRenderer, kShadowWidth, kShadowHeight);
    if (a.tileDisagreeing.empty())
        throw ProjectError("camera (azimuth_deg " + fmt("%g", s.camera.azimuthDeg) + ", elevation_deg " +
                           fmt("%g", s.camera.elevationDeg) + "): no 32-pixel tile of its " + std::to_string(kShadowWidth) +
                           " x " + std::to_string(kShadowHeight) + " view is a quarter terrain; the shadows are compared "
                           "on the terrain the camera sees");
    StudyPoint p;
    p.metric = StudyMetric::Shadow;
    p.seconds = a.shadowMilliseconds / 1000.0;
    // Depth maps of 32-bit texels, one layer a cascade.
    p.peakMemoryBytes = uint64_t(s.shadows.cascades) * uint64_t(s.shadows.mapResolution) * uint64_t(s.shadows.mapResolution) * 4u;
    // The horizon map: a byte a vertex in each frame slot.
    if (s.shadows.heightfield) p.peakMemoryBytes += shadowRenderer->renderer().horizonMapBytes();
    setErrors(p, a.tileDisagreeing);
    // The budget pays for the whole measurement (the traced view and a warm-up frame besides the
    // timed one), not the frame alone.
    learn("shadow", c.work, secondsSince(t0));
    const ShadowSettings& own = project.scene.shadows;
    p.current = s.shadows.cascades == own.cascades && s.shadows.mapResolution == own.mapResolution &&
                s.shadows.filter == own.filter && s.shadows.heightfield == own.heightfield;
    return p;
}

StudyPoint Study::measure(const Candidate& c) {
    StudyPoint p;
    switch (c.metric) {
        case StudyMetric::Irradiance: p = measureProbes(c); break;
        case StudyMetric::ErrorMapP95: p = measureErrorMap(c); break;
        case StudyMetric::AmbientOcclusion: p = measureAo(c); break;
        case StudyMetric::Lpv: p = measureLpv(c); break;
        case StudyMetric::Reflection: p = measureReflection(c); break;
        case StudyMetric::Shadow: p = measureShadow(c); break;
    }
    p.knob = c.knob;
    p.label = c.label;
    p.sets = c.sets;
    p.metric = c.metric;
    p.estimatedSeconds = c.estimate;
    return p;
}

void Study::run() {
    const SceneDescription& s = project.scene;
    prepare();
    if (cancelled()) throw BakeCancelled();
    placePoints();
    if (points.empty())
        throw PlacementError("probe_volumes '" + result.volume + "': no study point lies over the terrain inside the volume");
    bakeReference();
    if (cancelled()) throw BakeCancelled();

    // The project as it is: the point the plot marks, and the layout the error-map knob reads.
    report("current settings");
    Candidate cur;
    cur.knob = "current";
    cur.label = "current settings";
    StudyPoint cp = measure(cur);
    cp.current = true;
    result.points.push_back(cp);

    // The error map's truth: a map twice as dense as the project's (at least 32, at most 256).
    denseMapResolution = std::clamp(2 * std::max(s.bake.errorMapResolution, 16), 32, 256);
    std::vector<Candidate> todo = candidates(current->layout);
    if (original)
        for (Candidate& c : todo) c.sets = pinTargets(c.sets, *original, project, volumeIndex);
    {
        const double work = double(denseMapResolution) * denseMapResolution * current->meanRays;
        const double est = kSafety * work * rate["rays"];
        if (est < 0.25 * left()) {
            report("error map " + std::to_string(denseMapResolution) + " (the error map's truth)");
            uint64_t rays = 0;
            denseMap = mapStats(*this, denseMapResolution, &rays);
        } else {
            for (auto it = todo.begin(); it != todo.end();)
                it = it->metric == StudyMetric::ErrorMapP95 ? todo.erase(it) : it + 1;
            result.notStudied.push_back("error_map: its truth, a " + std::to_string(denseMapResolution) + "-point map (about " +
                                        fmt("%.0f", est) + " s), does not fit the budget");
        }
    }
    // The project's own error-map resolution measured too, so the knob marks it.
    if (denseMap && s.bake.errorMapResolution > 0 && s.bake.errorMapResolution < denseMapResolution) {
        bool listed = false;
        for (const Candidate& c : todo) listed |= c.metric == StudyMetric::ErrorMapP95 && c.param == s.bake.errorMapResolution;
        if (!listed) {
            Candidate c;
            c.knob = "error_map";
            c.label = "error map " + std::to_string(s.bake.errorMapResolution);
            c.metric = StudyMetric::ErrorMapP95;
            c.param = s.bake.errorMapResolution;
            c.work = double(c.param) * c.param * current->meanRays;
            todo.push_back(c);
        }
    }
    // Cheapest first within each knob, knobs in turn, so a short budget still sees every knob.
    std::map<std::string, std::vector<Candidate>> byKnob;
    std::vector<std::string> knobs;
    for (Candidate& c : todo) {
        if (!byKnob.count(c.knob)) knobs.push_back(c.knob);
        byKnob[c.knob].push_back(std::move(c));
    }
    for (auto& [k, list] : byKnob)
        std::stable_sort(list.begin(), list.end(), [](const Candidate& a, const Candidate& b) { return a.work < b.work; });
    std::map<std::string, size_t> next;
    bool any = true;
    while (any) {
        any = false;
        for (const std::string& k : knobs) {
            auto& list = byKnob[k];
            size_t& i = next[k];
            if (i >= list.size()) continue;
            any = true;
            Candidate& c = list[i++];
            if (cancelled()) throw BakeCancelled();
            if (c.metric == StudyMetric::Shadow && !shadowsUnavailable.empty()) continue;
            c.estimate = estimate(c);
            // A kind that has not run yet gets its first (cheapest) point whenever time is left.
            if (c.estimate < 0.0 ? left() <= 0.05 * options.budgetSeconds : c.estimate > left()) {
                StudySkip skip{c.knob, c.label, c.sets, std::max(c.estimate, 0.0),
                               c.estimate < 0.0 ? "no time left" : "estimated " + fmt("%.1f", c.estimate) + " s, " +
                                                                       fmt("%.1f", std::max(left(), 0.0)) + " s left"};
                result.skipped.push_back(std::move(skip));
                continue;
            }
            report(c.label);
            try {
                result.points.push_back(measure(c));
            } catch (const vk::VulkanUnavailable& e) {
                shadowsWithout(e.what());
            } catch (const vk::VulkanError& e) {
                shadowsWithout(e.what());
            } catch (const PlacementError& e) {
                result.skipped.push_back({c.knob, c.label, c.sets, c.estimate, e.what()});
            } catch (const ProjectError& e) {
                result.skipped.push_back({c.knob, c.label, c.sets, c.estimate, e.what()});
            }
        }
    }

    // The front of the probe trade, and the current error-map setting marked in its own series.
    std::vector<double> cost, error;
    for (const StudyPoint& p : result.points) {
        const bool probe = p.metric == StudyMetric::Irradiance;
        cost.push_back(probe ? p.seconds : NAN);
        error.push_back(probe ? p.errorP95 : NAN);
    }
    for (size_t i : paretoFront(cost, error)) result.points[i].pareto = true;
    for (StudyPoint& p : result.points)
        if (p.metric == StudyMetric::ErrorMapP95 && p.label == "error map " + std::to_string(s.bake.errorMapResolution))
            p.current = true;
    result.elapsedSeconds = elapsed();
    report("done");
}

std::string csvField(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string o = "\"";
    for (char c : s) o += c == '"' ? std::string("\"\"") : std::string(1, c);
    return o + "\"";
}

std::string htmlEscape(const std::string& s) {
    std::string o;
    for (char c : s) {
        switch (c) {
            case '&': o += "&amp;"; break;
            case '<': o += "&lt;"; break;
            case '>': o += "&gt;"; break;
            case '"': o += "&quot;"; break;
            default: o += c;
        }
    }
    return o;
}

std::string joinSets(const std::vector<std::string>& sets) {
    std::string o;
    for (const auto& s : sets) o += (o.empty() ? "" : " ") + s;
    return o;
}

std::string bytesText(uint64_t b) {
    if (b >= (uint64_t(1) << 20)) return fmt("%.1f MB", double(b) / double(1 << 20));
    if (b >= 1024) return fmt("%.1f kB", double(b) / 1024.0);
    return std::to_string(b) + " B";
}

}  // namespace

StudyResult runStudy(const Project& project, const StudyOptions& options, const StudyProgress& progress,
                     const std::atomic<bool>* cancel) {
    if (!(options.budgetSeconds >= kMinStudyBudget && options.budgetSeconds <= kMaxStudyBudget))
        throw ProjectError("study budget " + fmt("%g", options.budgetSeconds) + " s: must be in [" +
                           fmt("%g", kMinStudyBudget) + ", " + fmt("%g", kMaxStudyBudget) + "] seconds");
    const int threads = options.threads > 0 ? options.threads : tbb::info::default_concurrency();
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    // Targets are resolved first, so the study measures what the bake would bake.
    const Project resolved = resolveTargets(project, threads);
    Study st(resolved, options, progress, cancel);
    st.original = &project;
    st.result.budgetSeconds = options.budgetSeconds;
    st.result.threads = threads;
    st.run();
    return std::move(st.result);
}

nlohmann::json studyToJson(const StudyResult& r) {
    nlohmann::json points = nlohmann::json::array();
    for (const StudyPoint& p : r.points)
        points.push_back({{"knob", p.knob},
                          {"label", p.label},
                          {"set", p.sets},
                          {"current", p.current},
                          {"metric", studyMetricName(p.metric)},
                          {"time_s", p.seconds},
                          {"estimated_time_s", p.estimatedSeconds},
                          {"peak_memory_bytes", p.peakMemoryBytes},
                          {"output_bytes", p.outputBytes},
                          {"probes", p.probes},
                          {"error", {{"mean", p.errorMean}, {"p95", p.errorP95}, {"max", p.errorMax}}},
                          {"points", p.points},
                          {"pareto", p.pareto}});
    nlohmann::json skipped = nlohmann::json::array();
    for (const StudySkip& s : r.skipped)
        skipped.push_back({{"knob", s.knob}, {"label", s.label}, {"set", s.sets},
                           {"estimated_time_s", s.estimatedSeconds}, {"reason", s.reason}});
    nlohmann::json metrics = nlohmann::json::object();
    for (StudyMetric m : kStudyMetrics) metrics[studyMetricName(m)] = studyMetricMeaning(m);
    return {{"generator", std::string("Terralux ") + TERRALUX_VERSION},
            {"project", r.project},
            {"terrain", r.terrain},
            {"volume", r.volume},
            {"budget_s", r.budgetSeconds},
            {"elapsed_s", r.elapsedSeconds},
            {"threads", r.threads},
            {"reference",
             {{"points", r.reference.points},
              {"rays_per_point", r.reference.raysPerPoint},
              {"height_m", r.reference.height},
              {"time_s", r.reference.seconds}}},
            {"metrics", metrics},
            {"points", points},
            {"skipped", skipped},
            {"not_studied", r.notStudied}};
}

std::string studyCsv(const StudyResult& r) {
    std::ostringstream o;
    o << "knob,label,set,current,metric,time_s,peak_memory_bytes,output_bytes,probes,error_mean,error_p95,error_max,"
         "points,pareto\n";
    for (const StudyPoint& p : r.points)
        o << csvField(p.knob) << ',' << csvField(p.label) << ',' << csvField(joinSets(p.sets)) << ','
          << (p.current ? 1 : 0) << ',' << studyMetricName(p.metric) << ',' << fmt("%.6g", p.seconds) << ','
          << p.peakMemoryBytes << ',' << p.outputBytes << ',' << p.probes << ',' << fmt("%.6g", p.errorMean) << ','
          << fmt("%.6g", p.errorP95) << ',' << fmt("%.6g", p.errorMax) << ',' << p.points << ',' << (p.pareto ? 1 : 0)
          << '\n';
    return o.str();
}

std::string studyHtml(const StudyResult& r, const std::string& plotFile) {
    std::ostringstream o;
    o << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>Terralux study: "
      << htmlEscape(r.project.empty() ? r.terrain : r.project) << "</title>\n<style>"
      << "body{font-family:sans-serif;margin:2em;max-width:72em}table{border-collapse:collapse;font-size:90%}"
      << "td,th{border:1px solid #bbb;padding:2px 6px;text-align:right}td.l,th.l{text-align:left}"
      << "tr.front{background:#e8f4e0}tr.current{font-weight:bold}</style></head><body>\n";
    o << "<h1>Speed/accuracy study</h1>\n<p>Project <b>" << htmlEscape(r.project.empty() ? "(none)" : r.project)
      << "</b>, terrain " << htmlEscape(r.terrain) << ", probe volume <b>" << htmlEscape(r.volume) << "</b>; "
      << r.points.size() << " settings measured in " << fmt("%.1f", r.elapsedSeconds) << " s of a "
      << fmt("%.0f", r.budgetSeconds) << " s budget on " << r.threads << " threads. Reference: "
      << r.reference.points << " points " << fmt("%.1f", r.reference.height) << " m above the ground, "
      << r.reference.raysPerPoint << " path-traced rays each.</p>\n";
    o << "<p><img src=\"" << htmlEscape(plotFile) << "\" alt=\"error against time, log-log\" width=\"960\"></p>\n";
    o << "<p>Error (p95) against time. Green rows lie on the Pareto front of the probe settings: nothing "
         "else is both faster and more accurate. Bold: the project's settings. Each setting changes only "
         "what its <code>--set</code> says.</p>\n<ul>\n";
    for (StudyMetric m : kStudyMetrics)
        o << "<li><code>" << studyMetricName(m) << "</code>: " << htmlEscape(studyMetricMeaning(m)) << "</li>\n";
    o << "</ul>\n<table><tr><th class=l>knob</th><th class=l>setting</th><th>time s</th><th>peak memory</th>"
         "<th>output</th><th>probes</th><th class=l>metric</th><th>error mean</th><th>p95</th><th>max</th>"
         "<th class=l>--set</th></tr>\n";
    for (const StudyPoint& p : r.points) {
        o << "<tr" << (p.pareto ? " class=front" : p.current ? " class=current" : "") << "><td class=l>"
          << htmlEscape(p.knob) << "</td><td class=l>" << htmlEscape(p.label) << "</td><td>" << fmt("%.3f", p.seconds)
          << "</td><td>" << bytesText(p.peakMemoryBytes) << "</td><td>" << bytesText(p.outputBytes) << "</td><td>"
          << p.probes << "</td><td class=l>" << studyMetricName(p.metric) << "</td><td>" << fmt("%.2f %%", 100 * p.errorMean)
          << "</td><td>" << fmt("%.2f %%", 100 * p.errorP95) << "</td><td>" << fmt("%.2f %%", 100 * p.errorMax)
          << "</td><td class=l><code>" << htmlEscape(joinSets(p.sets)) << "</code></td></tr>\n";
    }
    o << "</table>\n";
    if (!r.skipped.empty()) {
        o << "<h2>Skipped</h2>\n<ul>\n";
        for (const StudySkip& s : r.skipped)
            o << "<li>" << htmlEscape(s.label) << " (" << htmlEscape(s.knob) << "): " << htmlEscape(s.reason) << "</li>\n";
        o << "</ul>\n";
    }
    if (!r.notStudied.empty()) {
        o << "<h2>Not studied</h2>\n<ul>\n";
        for (const std::string& s : r.notStudied) o << "<li>" << htmlEscape(s) << "</li>\n";
        o << "</ul>\n";
    }
    o << "</body></html>\n";
    return o.str();
}

std::string studySummary(const StudyResult& r) {
    std::ostringstream o;
    o << "study of '" << r.volume << "' on " << r.terrain << ": " << r.points.size() << " settings in "
      << fmt("%.1f", r.elapsedSeconds) << " s (budget " << fmt("%.0f", r.budgetSeconds) << " s), reference "
      << r.reference.points << " points x " << r.reference.raysPerPoint << " rays\n";
    // Columns as wide as their longest entry, counted in characters (a label may hold a '²').
    auto width = [](const std::string& t) {
        return size_t(std::count_if(t.begin(), t.end(), [](char ch) { return (static_cast<unsigned char>(ch) & 0xC0) != 0x80; }));
    };
    auto pad = [&](const std::string& t, size_t w) { return t + std::string(w > width(t) ? w - width(t) : 0, ' '); };
    size_t knobW = 4, labelW = 7;
    for (const StudyPoint& p : r.points) knobW = std::max(knobW, width(p.knob)), labelW = std::max(labelW, width(p.label));
    char line[256];
    std::snprintf(line, sizeof line, " %9s %10s %10s %9s %9s\n", "time s", "memory", "output", "err mean", "err p95");
    o << "  " << pad("knob", knobW) << " " << pad("setting", labelW) << line;
    for (const StudyPoint& p : r.points) {
        std::snprintf(line, sizeof line, " %9.3f %10s %10s %8.2f%% %8.2f%%%s\n", p.seconds,
                      bytesText(p.peakMemoryBytes).c_str(), bytesText(p.outputBytes).c_str(), 100 * p.errorMean,
                      100 * p.errorP95, p.pareto ? "  front" : "");
        o << (p.current ? "* " : "  ") << pad(p.knob, knobW) << " " << pad(p.label, labelW) << line;
    }
    for (const StudySkip& s : r.skipped) o << "  skipped " << s.label << ": " << s.reason << "\n";
    for (const std::string& s : r.notStudied) o << "  not studied: " << s << "\n";
    o << "  (* the project's settings; front: on the Pareto front of time against p95 error)\n";
    return o.str();
}

std::vector<std::filesystem::path> writeStudy(const StudyResult& r, const std::filesystem::path& dir,
                                              const StudyPlotWriter& writePlot) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw FileWriteError(dir.string() + ": cannot create the folder: " + ec.message());
    std::vector<std::filesystem::path> files;
    if (writePlot) {
        writePlot(r, dir / "study.png");
        files.push_back(dir / "study.png");
    }
    writeFileAtomically(dir / "study.json", studyToJson(r).dump(2) + "\n");
    files.push_back(dir / "study.json");
    writeFileAtomically(dir / "study.csv", studyCsv(r));
    files.push_back(dir / "study.csv");
    writeFileAtomically(dir / "study.html", studyHtml(r, "study.png"));
    files.push_back(dir / "study.html");
    return files;
}

}  // namespace terralux
