#include "BakeJob.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <functional>
#include <map>
#include <optional>
#include <memory>
#include <numbers>
#include <sstream>
#include <cmath>
#include <iomanip>
#include <thread>

#include <glm/trigonometric.hpp>
#include <glm/vector_relational.hpp>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include "AtomicFile.h"
#include "EnvironmentImage.h"
#include "GltfExport.h"
#include "LpvConsoleVariables.h"
#include "OutputFolder.h"
#include "ParameterTable.h"
#include "ProbeDiagnosticsFile.h"
#include "ReflectionProbeFile.h"
#include "SceneLighting.h"
#include "ShProbeFile.h"
#include "ShaderMath.h"
#include "TerrainLoading.h"
#include "bake/AdaptivePlacement.h"
#include "bake/DiffuseBake.h"
#include "bake/HeightfieldTracer.h"
#include "bake/ProbeDiagnostics.h"
#include "bake/ProbePlacement.h"
#include "bake/ReflectionBake.h"
#include "bake/SphereSampling.h"
#include "bake/TargetSearch.h"
#include "lpv/Lpv.h"
#include "scene/OrbitCamera.h"
#include "water/Water.h"

#ifndef TERRALUX_VERSION
#define TERRALUX_VERSION "0.0.0"
#endif

namespace terralux {

bool errorIsHigh(const ErrorMapStats& m) {
    return m.points > 0 && (m.mean > kSuggestAboveMeanError || m.p95 > kSuggestAboveP95Error);
}

namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
}

constexpr const char* kReferenceNote =
    "not computed: with quality reference the probes are the reference itself; standard_error "
    "gives their Monte Carlo error";

nlohmann::json stats(const std::vector<float>& v) {
    const Spread s = spreadOf(v);
    return {{"mean", s.mean}, {"p95", s.p95}, {"max", s.max}};
}

// The .shprobe of a volume: valid probes only, occupancy pointing at their compacted indices.
ShProbeGrid toGrid(const ProbeLayout& layout, const std::vector<sh::ShRgb>& coeffs,
                   const ExportSettings& ex) {
    ShProbeGrid g;
    g.dims = glm::uvec3(layout.cellDims[0], layout.cellDims[1], layout.cellDims[2]);
    g.origin = layout.cellOrigin;
    g.spacing = layout.cellSize;
    g.defaultScale = float(ex.defaultScale);
    g.defaultAmbient = float(ex.defaultAmbient);
    for (size_t i = 0; i < layout.positions.size(); ++i) {
        if (!layout.valid[i]) continue;
        ShProbeRecord r;
        r.coeffs = coeffs[i].c;
        r.scale = g.defaultScale;
        r.ambient = g.defaultAmbient;
        g.probes.push_back(r);
    }
    g.occupancy = layout.compactedOccupancy();
    return g;
}

// What an image sky's sun asks of the author, for the project's lighting or a scenario's (`where`
// "" or "scenarios[i]."): followed but too wide to be a sun (the probes keep it, lightingOf), or
// not followed though it gives level ground more light than the rest of the image (baked into the
// probes, its shadows are as wide as their spacing).
void imageSunWarnings(const SceneDescription& scene, const BakeLighting& lighting, const std::string& where,
                      std::vector<std::string>& warnings) {
    if (scene.sky.mode != SkyMode::Hdr) return;
    if (scene.sun.followSky) {
        if (!lighting.sky.hasGlow()) return;
        char why[160];
        std::snprintf(why, sizeof why, "the image's glow spreads %.1f° about its centre, wider than a sun's %.0f°",
                      glm::degrees(double(lighting.sky.glowSun().angularRadius)), Sky::kMaxSunRadiusDeg);
        warnings.push_back(where + "sun.follow_sky under " + where + "sky.hdr: " + why +
                           ": it stays in the sky the probes see, and no sun lights besides it");
        return;
    }
    if (!lighting.sky.glowIsSun()) return;
    const SunLight glow = lighting.sky.glowSun();
    const glm::vec3 fromSun = glow.illuminance * std::max(0.0f, glow.direction.y);
    const glm::vec3 fromSky = lighting.sky.withoutGlow().openIrradianceUp();
    if (glsl::rec709Luminance(fromSun) <= glsl::rec709Luminance(fromSky)) return;
    const ImageSun read = imageSunOf(glow, double(lighting.sky.glowShare()));
    char at[96];
    std::snprintf(at, sizeof at, "azimuth %.1f°, %.1f° up, %.0f %% of its light", read.azimuthDeg, read.elevationDeg,
                  100.0 * read.shareOfSky);
    warnings.push_back(where + "sun.follow_sky: false under " + where + "sky.hdr, whose image has a sun (" + at +
                       "): the probes hold its light and its shadows, blurred over their spacing, and the authored sun lights "
                       "besides it; set " + where + "sun.follow_sky=true to light with the image's sun, shadowed at the pixel");
}

// What a bake needs before it places a probe: terrain, lighting, tracer, quality, volumes.
struct BakeSetup {
    DemImportResult terrain;  // a tile's core when tiled
    // A tiled bake: the terrain within the near halo, which the tracer holds (by address: heap)...
    std::unique_ptr<Heightfield> tracedTerrain;
    // ... and, where the halo reaches further, the region's overview over the whole halo, which
    // the tracer traces beyond the near halo.
    std::unique_ptr<Heightfield> farTerrain;
    std::unique_ptr<HeightfieldTracer> farTracer;
    // ... and the whole region, which the exported lighting (fog base, shadow range, LPV, water
    // level) describes, the same for every tile.
    std::unique_ptr<Heightfield> region;
    std::optional<TileWindow> tileWindow;
    nlohmann::json tileReport;
    BakeLighting lighting;
    std::unique_ptr<HeightfieldTracer> tracer;  // bakeSceneOf's, which `lighting` points at
    BakeQuality q;
    bool referenceMode = false;
    std::vector<const ProbeVolumeSettings*> volumes;
    double prepareSeconds = 0.0;  // loading the terrain, sky and albedo
};

void prepare(const Project& project, BakeSetup& b, const std::function<void(const std::string&, double)>& report,
             const std::function<bool()>& cancelled, const std::optional<TileSpec>& tile = std::nullopt,
             bool writesSummary = true) {
    const SceneDescription& scene = project.scene;
    // A scene built in code has not met the parameter table's rules, as a file or --set has:
    // take it through them, so a bake refuses what loading the project would (a grid past
    // its probe limit, a value out of range) instead of baking it.
    (void)sceneFromJson(sceneToJson(scene), "project", nullptr);
    const auto start = Clock::now();
    report("loading terrain", 0.0);
    if (tile) {
        // Out of core where the DEM allows it: the grid from its header and one streamed pass,
        // then only the tile's traced window read (DemImportOptions::window). The region's grid
        // and overview are computed by the first tile and read by the others; a dry run writes
        // nothing.
        RegionSummary region = regionSummary(project, project.outDir().parent_path(), writesSummary);
        const DemGrid& grid = region.grid;
        const Heightfield& overview = region.overview;
        try {
            b.tileWindow = tileWindow(grid, *tile, std::max(overview.cellSizeX(), overview.cellSizeZ()));
        } catch (const std::invalid_argument& e) {
            throw ProjectError(e.what());
        }
        const TileWindow& w = *b.tileWindow;
        b.tileReport = tileReport(*tile, w, grid);
        b.terrain = loadProjectTerrain(project, GridWindow{w.tracedCol0, w.tracedRow0, w.tracedCols, w.tracedRows});
        b.tileReport["window_read"] = b.terrain.source.windowRead;
        b.tracedTerrain = std::make_unique<Heightfield>(std::move(b.terrain.heightfield));
        b.terrain.heightfield =
            b.tracedTerrain->window(w.col0 - w.tracedCol0, w.row0 - w.tracedRow0, w.cols, w.rows);
        if (w.far) {
            const GridWindow o = overviewWindow(w, grid, overview);
            b.farTerrain = std::make_unique<Heightfield>(overview.window(o.col0, o.row0, o.cols, o.rows));
            b.farTracer = std::make_unique<HeightfieldTracer>(*b.farTerrain,
                                                              HeightfieldTracer::Options{project.scene.terrain.skirt});
            b.tileReport["far_window"] = {{"col0", o.col0}, {"row0", o.row0}, {"cols", o.cols}, {"rows", o.rows},
                                          {"cell_m", {overview.cellSizeX(), overview.cellSizeZ()}}};
        }
        b.tileReport["region_summary"] = region.cached ? "read" : "computed";
        // The region as the exported lighting sees it, the same in every tile.
        b.region = std::make_unique<Heightfield>(std::move(region.overview));
    } else {
        b.terrain = loadProjectTerrain(project);
    }
    // A terrain the scene cannot carry is refused now, in the dry run too, not after the probes
    // (a 13 459 × 18 391 mesh failed at the export, three and a half minutes into the bake).
    const Heightfield& meshed = b.terrain.heightfield;
    if (scene.exportSettings.gltf && meshed.width() > 1 && meshed.depth() > 1)
        checkTerrainMesh(meshed, GltfSceneInput{}.meshMaxVertices, project.outDir() / "scene.gltf");
    if (cancelled()) throw BakeCancelled();
    report("loading sky and albedo", 0.01);
    BakeScene traced = bakeSceneOf(project, b.tracedTerrain ? *b.tracedTerrain : b.terrain.heightfield, false,
                                   b.farTracer.get());
    b.lighting = traced.lighting;
    b.tracer = std::move(traced.tracer);
    // Water that "auto" finds sits at the region's level, not a tile's own.
    if (b.region) b.lighting.water = bakeWaterOf(project, *b.region);
    if (cancelled()) throw BakeCancelled();
    // Every sun can be placed over this terrain, the scenarios' included, before any probe.
    checkSunPlaces(scene, b.terrain.heightfield);
    b.q = qualityOf(scene.bake);
    b.referenceMode = scene.bake.quality == QualityPreset::Reference;
    for (const auto& v : scene.probeVolumes)
        if (v.enabled) b.volumes.push_back(&v);
    if (b.volumes.empty() && !scene.reflectionProbes.enabled)
        throw ProjectError("probe_volumes: no enabled volume; enable one or add one (or reflection probes) to bake");
    b.prepareSeconds = secondsSince(start);
}

uint64_t volumeSeed(size_t index) { return splitmix64(0x7E77A1ABull + index); }

// estimateBake on a prepared setup: what a suggestion reuses instead of loading the terrain,
// albedo and tracer a second time (which doubled a bake's peak memory).
// `full` (the dry run): the bake's own cache built and timed, and a terrain grid's map baked to
// know whether the bake will measure a suggestion. Otherwise (a suggestion's estimate, inside a
// bake) the cache is a small one scaled by its points and no suggestion is counted.
BakeEstimate estimateWith(const BakeRequest& request, BakeSetup& setup, int threads, bool full);

// The mean error a suggested terrain grid aims at.
constexpr double kSuggestTargetMeanError = 0.02;
// Trial grids a suggestion may measure before it settles.
constexpr int kSuggestTrials = 3;


// A denser terrain grid for a volume whose interpolation error is high, measured, not modelled:
// each trial grid is placed and baked like the volume (same rays, seed, cache and deringing) and
// its error map taken over the same points, against the same truths (measureErrorMap's truth
// cache), so its figures are what the bake with that setting reports, up to the finer cache a
// denser grid earns. The first trial grows each side by sqrt(mean / target) (bilinear error falls
// with the square of the spacing); later ones by the exponent the last two grids showed, for on
// steep terrain the error falls far slower than that. Within the 4096-probe limit; at most
// kSuggestTrials grids. The fewest probes that meet the target, else the last grid measured.
struct GridSuggestion {
    std::vector<std::string> sets;
    size_t probes = 0;
    ErrorMapStats error;
    bool meets = false;
    int trials = 0;
    uint64_t rays = 0;
};

// The grid a suggestion tries next from an ax x az grid of `side` probes a side (geometric mean)
// whose map errs `error` on average: each side grown by (error / target)^(1 / exponent) (bilinear
// error falls with the square of the spacing, exponent 2, until trials measure another), then
// shrunk to `maxProbes`, the terrain-grid limit or a tile's share of it (`capped`).
std::array<double, 2> grownGrid(int ax, int az, double side, double error, double exponent, bool& capped,
                                int maxProbes = kMaxTerrainGridProbes) {
    const double grow = std::pow(error / kSuggestTargetMeanError, 1.0 / exponent);
    double nx = std::ceil(ax * side / std::sqrt(double(ax) * az) * grow);
    double nz = std::ceil(az * side / std::sqrt(double(ax) * az) * grow);
    const double fit = std::sqrt(double(maxProbes) / (nx * nz));
    capped = fit < 1.0;
    if (capped) nx = std::floor(nx * fit), nz = std::floor(nz * fit);
    return {nx, nz};
}

std::optional<GridSuggestion> denserGrid(
    const ProbeVolumeSettings& v, size_t index, const ProbeLayout& layout, const ErrorMapStats& now,
    const std::function<std::optional<ErrorMapStats>(const ProbeVolumeSettings&, size_t&, uint64_t&)>& measure,
    int maxProbes) {
    const std::string at = "probe_volumes[" + std::to_string(index) + "].";
    const int ax = layout.probeDims[0], az = layout.probeDims[2];
    double side = std::sqrt(double(ax) * az), error = now.mean, exponent = 2.0;
    std::optional<GridSuggestion> best;
    GridSuggestion last;
    int trials = 0;
    uint64_t rays = 0;
    for (; trials < kSuggestTrials; ++trials) {
        bool capped = false;
        const auto [nx, nz] = grownGrid(ax, az, side, error, exponent, capped, maxProbes);
        if (nx * nz <= side * side + 0.5) break;  // no denser grid left to try
        ProbeVolumeSettings candidate = v;
        candidate.gridDims = {int(nx), 1, int(nz)};
        std::vector<std::string> sets = {at + "grid_dims=" + std::to_string(int(nx)) + "," + std::to_string(int(nz))};
        if (v.spacing) {
            // Keep the footprint: the spacing shrinks as the count grows.
            candidate.spacing = glm::vec3(v.spacing->x * float(ax - 1) / float(std::max(nx - 1.0, 1.0)), 0.0f,
                                          v.spacing->z * float(az - 1) / float(std::max(nz - 1.0, 1.0)));
            std::ostringstream o;
            o << std::setprecision(6) << candidate.spacing->x << "," << candidate.spacing->z;
            sets.push_back(at + "spacing=" + o.str());
        }
        size_t probes = 0;
        const std::optional<ErrorMapStats> m = measure(candidate, probes, rays);
        if (!m || m->points == 0) break;
        last = {sets, probes, *m, m->mean <= kSuggestTargetMeanError, 0, 0};
        if (last.meets) {
            best = last;
            ++trials;
            break;
        }
        const double newSide = std::sqrt(nx * nz);
        if (m->mean < error && newSide > side)
            exponent = std::clamp(std::log(error / m->mean) / std::log(newSide / side), 0.25, 2.0);
        side = newSide;
        error = m->mean;
        if (capped) {
            ++trials;
            break;  // at the limit: nothing denser to measure
        }
    }
    if (!best && !last.sets.empty()) best = last;
    if (best) {
        best->trials = trials;
        best->rays = rays;
    }
    return best;
}

nlohmann::json suggestionReport(const GridSuggestion& g, const BakeEstimate& e, const VolumeEstimate& ve) {
    return {{"set", g.sets},
            {"probes", ve.probes},
            {"probes_max", ve.probesMax},
            {"estimated_time_s", e.seconds},
            {"estimated_max_time_s", e.secondsMax},
            {"predicted_error", {{"mean", g.error.mean}, {"p95", g.error.p95}, {"max", g.error.max},
                                 {"points", g.error.points}}},
            {"target_mean", kSuggestTargetMeanError},
            {"meets_target", g.meets},
            {"trials", g.trials},
            {"rays", g.rays}};
}

// The suggestion's report entry: its measured error, and the probes and time the dry run's
// calibration estimates for the project with its settings.
nlohmann::json suggestions(const BakeRequest& request, size_t index, const std::optional<GridSuggestion>& grid,
                           BakeSetup& setup, int threads) {
    nlohmann::json out = nlohmann::json::array();
    if (!grid) return out;
    const ProbeVolumeSettings& v = request.project.scene.probeVolumes[index];
    BakeRequest r = request;
    nlohmann::json doc = projectToJson(r.project);
    for (const auto& s : grid->sets) applyOverride(doc, s);
    r.project.scene = sceneFromJson(doc, "suggestion", nullptr);
    // Only the probe volumes differ from the bake's own: its terrain, sky and tracer stand.
    const std::vector<const ProbeVolumeSettings*> own = setup.volumes;
    setup.volumes.clear();
    for (const auto& candidate : r.project.scene.probeVolumes)
        if (candidate.enabled) setup.volumes.push_back(&candidate);
    try {
        const BakeEstimate e = estimateWith(r, setup, threads, false);
        setup.volumes = own;
        for (const auto& x : e.volumes)
            if (x.name == v.name) out.push_back(suggestionReport(*grid, e, x));
    } catch (const std::exception&) {
        // A suggestion the estimate refuses (a placement limit) is not made.
        setup.volumes = own;
    }
    // A tile measured its own share of the grid: the project is the region's, so the suggestion
    // names the region's grid_dims whose share this tile is (tile_set keeps the tile's).
    const std::string dims = "probe_volumes[" + std::to_string(index) + "].grid_dims=";
    if (setup.tileWindow)
        for (auto& s : out) {
            s["tile_set"] = s["set"];
            for (auto& set : s["set"]) {
                const std::string text = set.get<std::string>();
                int nx = 0, nz = 0;
                if (text.rfind(dims, 0) != 0 || std::sscanf(text.c_str() + dims.size(), "%d,%d", &nx, &nz) != 2) continue;
                const std::array<int, 2> region = regionTerrainGridDims({nx, nz}, *setup.tileWindow);
                set = dims + std::to_string(region[0]) + "," + std::to_string(region[1]);
            }
        }
    return out;
}

// A volume whose every probe is inside the terrain would export an empty grid and report its
// error as 0 %: refuse it, naming the setting that put the probes there.
void requireProbes(const SceneDescription& scene, const ProbeVolumeSettings& v, const ProbeLayout& layout) {
    if (layout.validCount() > 0) return;
    const std::string at = "probe_volumes[" + std::to_string(&v - scene.probeVolumes.data()) + "]";
    std::ostringstream fix;
    if (followsSurface(v.placement))
        fix << "raise " << at << ".height_offset (now " << v.heightOffset << " m)";
    else
        fix << "move " << at << ".origin up or enlarge the volume";
    throw PlacementError("probe_volumes '" + v.name + "': all " + std::to_string(layout.positions.size()) +
                         " probes are inside the terrain, none is left to bake; " + fix.str());
}

// Bakes probes seeded by key (adaptive leaves, interpolation-error points).
ProbeBaker keyedBaker(const BakeSetup& b, const IrradianceCache* cache, const ProbeRays& rays, uint64_t seed,
                      const BakeControl& control) {
    return seededBaker(b.lighting, cache, b.q.bounces, rays, seed, control, b.referenceMode);
}

ProbeRays raysOf(const BakeSetup& b, const ProbeVolumeSettings& v);

// Probes in groups of three digits: "3 914".
std::string grouped(uint64_t n) {
    std::string d = std::to_string(n), out;
    for (size_t i = 0; i < d.size(); ++i) {
        if (i && (d.size() - i) % 3 == 0) out += ' ';
        out += d[i];
    }
    return out;
}

std::string percent(double x) {
    std::ostringstream o;
    o.setf(std::ios::fixed);
    o.precision(1);
    o << 100.0 * x << " %";
    return o.str();
}

// Map points a side for the search's trials: coarse, since a trial only has to rank layouts.
int searchMapResolution(const BakeSettings& b) {
    constexpr int kSearchMap = 32;
    return b.errorMapResolution > 0 ? std::min(b.errorMapResolution, kSearchMap) : kSearchMap;
}

// The trials' baker: seeded like the bake's, windowed like its probes, so a trial's map measures
// the probes the bake writes.
ProbeBaker trialBaker(const BakeSetup& b, const IrradianceCache* cache, const ProbeRays& rays, uint64_t seed,
                      bool dering) {
    return deringedBaker(seededBaker(b.lighting, cache, b.q.bounces, rays, seed, BakeControl{}, b.referenceMode),
                         dering);
}

// The small irradiance cache the search bakes with (the bake's own is sized by its probes, which
// the search decides).
std::unique_ptr<IrradianceCache> searchCache(const BakeSetup& b) {
    if (b.referenceMode || b.q.bounces <= 0) return nullptr;
    constexpr int kSearchCacheResolution = 32;
    return std::make_unique<IrradianceCache>(b.lighting, kSearchCacheResolution, b.q.cacheRays, b.q.sunSamples,
                                             b.q.bounces - 1, BakeControl{});
}

constexpr int kOfferMaxProbes = kMaxBoxGridProbes;

// bake.target_error's trials: at most this many of the volumes' own probes, rays in
// [kMinTargetRays, kMaxTargetRays] (the top is the standard-error factors' calibration count), the
// bounce trials at kBounceTrialRays each (the same rays for b and b + 1, so their difference has
// little noise) over a cache of at most kBounceTrialCache points a side.
constexpr size_t kPilotProbes = 64;
constexpr int kMinTargetRays = 16, kMaxTargetRays = 16384;
constexpr int kBounceTrialRays = 512;
constexpr int kBounceTrialCache = 48;

// Chooses rays and bounces from bake.target_error, into setup.q, and clears the volumes' own
// ray_count, which the target replaces (in `scene`, whose volumes `setup` points at).
std::optional<SamplingChoice> chooseSampling(SceneDescription& scene, BakeSetup& setup,
                                             const std::function<void(const std::string&)>& phase) {
    if (!scene.bake.targetError) return std::nullopt;
    const double target = *scene.bake.targetError;
    const std::string at = "bake.target_error = " + nlohmann::json(target).dump();
    if (setup.referenceMode)
        throw ProjectError(at + ": the reference preset path-traces every bounce to convergence; use draft, "
                                "standard or high with a target, or unset bake.target_error");
    if (setup.volumes.empty())
        throw ProjectError(at + ": it measures the probes of a probe volume, and none is enabled");
    phase("choosing rays and bounces");
    const auto start = Clock::now();
    const Heightfield& hf = setup.terrain.heightfield;
    SamplingChoice c;
    c.target = target;

    // What the target replaces, for the report.
    std::ostringstream replaced;
    const BakeQuality preset = qualityPreset(scene.bake.quality);
    replaced << (scene.bake.rays ? "bake.rays " + std::to_string(*scene.bake.rays)
                                 : "the " + std::string(qualityName(scene.bake.quality)) + " preset's " +
                                       raysDescription(preset.probeRays()))
             << " and "
             << (scene.bake.bounces ? "bake.bounces " + std::to_string(*scene.bake.bounces)
                                    : std::to_string(preset.bounces) + " bounces");
    for (const auto* v : setup.volumes) {
        const size_t index = size_t(v - scene.probeVolumes.data());
        if (!v->rayCount) continue;
        replaced << "; probe_volumes[" << index << "].ray_count " << *v->rayCount;
        scene.probeVolumes[index].rayCount.reset();
    }
    c.replaced = replaced.str();

    // The pilot probes: spread evenly over every enabled volume's valid probes as placed now.
    std::vector<glm::vec3> all;
    for (const auto* v : setup.volumes) {
        const ProbeLayout layout = placeProbes(*v, hf);
        for (size_t i = 0; i < layout.positions.size(); ++i)
            if (layout.valid[i]) all.push_back(layout.positions[i]);
    }
    std::vector<glm::vec3> pilot;
    for (size_t k = 0; k < std::min(all.size(), kPilotProbes); ++k)
        pilot.push_back(all[k * all.size() / std::min(all.size(), kPilotProbes)]);
    const std::vector<uint8_t> valid(pilot.size(), 1);
    c.pilotProbes = pilot.size();
    constexpr uint64_t kPilotSeed = 0x9170AB5Eull;

    // Bounces: caches after 0..kMaxBounces-1 gathers from one set of rays; b bounces read the
    // cache after b - 1 gathers (0 bounces: sky visibility, no cache).
    const std::vector<IrradianceCache> caches = IrradianceCache::byGathers(
        setup.lighting, std::min(setup.q.cacheResolution, kBounceTrialCache), setup.q.cacheRays, setup.q.sunSamples,
        kMaxBounces - 1, BakeControl{});
    auto cacheFor = [&](int bounces) { return bounces > 0 ? &caches[size_t(bounces - 1)] : nullptr; };
    std::map<int, ProbeBake> byBounces;
    auto bakedAt = [&](int bounces) -> const ProbeBake& {
        auto it = byBounces.find(bounces);
        if (it == byBounces.end())
            it = byBounces.emplace(bounces, bakeProbes(setup.lighting, cacheFor(bounces), bounces, pilot, valid,
                                                       kBounceTrialRays, kPilotSeed, BakeControl{})).first;
        return it->second;
    };
    c.bounceSearch = searchBounces(target, kMaxBounces, [&](int b) {
        const double change = compareToReference(bakedAt(b).sh, bakedAt(b + 1).sh, valid).p95;
        byBounces.erase(b);
        return change;
    });
    c.bounces = c.bounceSearch.chosen;

    // Rays, at those bounces.
    c.raySearch = searchRays(target, kMinTargetRays, kMaxTargetRays, setup.q.rays, [&](int rays) {
        const ProbeBake b = bakeProbes(setup.lighting, cacheFor(c.bounces), c.bounces, pilot, valid, rays,
                                       kPilotSeed, BakeControl{});
        return spreadOf(b.standardError).p95;
    });
    c.rays = c.raySearch.chosen;
    c.met = c.raySearch.met && c.bounceSearch.met;
    c.seconds = secondsSince(start);

    std::ostringstream sum;
    sum << grouped(uint64_t(c.rays)) << " rays (p95 standard error " << percent(c.raySearch.error) << "), "
        << c.bounces << " bounce" << (c.bounces == 1 ? "" : "s");
    if (c.bounceSearch.met)
        sum << " (one more adds " << percent(c.bounceSearch.error) << ")";
    else
        sum << " (the most allowed; one more still adds " << percent(c.bounceSearch.error) << ")";
    c.summary = sum.str();

    setup.q.rays = c.rays;
    setup.q.targetError = 0.0f;
    setup.q.bounces = c.bounces;
    return c;
}

// Chooses grid_dims or adaptive.tolerance for every enabled volume with a target_error, in place
// in `scene` (whose volumes `setup` points at). The project's terrain, lighting and tracer are
// the setup's; nothing is loaded again.
std::map<size_t, TargetChoice> chooseTargets(SceneDescription& scene, BakeSetup& setup,
                                             const std::function<void(const std::string&)>& phase) {
    std::map<size_t, TargetChoice> out;
    const Heightfield& hf = setup.terrain.heightfield;
    std::unique_ptr<IrradianceCache> cache;
    for (size_t vi = 0; vi < setup.volumes.size(); ++vi) {
        const size_t index = size_t(setup.volumes[vi] - scene.probeVolumes.data());
        ProbeVolumeSettings& v = scene.probeVolumes[index];
        if (!v.targetError) continue;
        const std::string at = "probe_volumes[" + std::to_string(index) + "]";
        if (v.placement == ProbePlacement::Box)
            throw ProjectError(at + ".target_error = " + nlohmann::json(*v.targetError).dump() +
                               ": applies to terrain, surface and adaptive placements; a box volume takes " + at +
                               ".grid_dims (or set " + at + ".placement=surface)");
        phase("choosing placement '" + v.name + "'");
        const auto start = Clock::now();
        if (!cache) cache = searchCache(setup);
        TargetChoice c;
        c.target = *v.targetError;
        c.mapResolution = searchMapResolution(scene.bake);
        const uint64_t seed = volumeSeed(vi);
        // Trials trace the least rays as a fixed count, as the error map does (measureVolumeErrorMap):
        // the bake's own probes then err no more than the trials that chose them.
        const ProbeBaker baker =
            trialBaker(setup, cache.get(), ProbeRays(raysOf(setup, v).rays), seed, scene.bake.deringing);
        PlacementSearch search;
        std::ostringstream value;
        if (v.placement == ProbePlacement::Terrain) {
            c.setting = "grid_dims";
            c.replaced = std::to_string(v.gridDims[0]) + "," + std::to_string(v.gridDims[2]);
            search = searchTerrainGrid(hf, c.target, kMaxTerrainGridProbes, std::max(v.gridDims[0], v.gridDims[2]),
                                       [&](const std::array<int, 3>& d) {
                                           return measureGridTrial(v, hf, d, baker, c.mapResolution, seed);
                                       });
            // The bake judges its own, finer map: confirm there, a probe a side more while it misses.
            const int fine = scene.bake.errorMapResolution;
            if (fine > c.mapResolution) {
                confirmTerrainGrid(hf, c.target, kMaxTerrainGridProbes, search, [&](const std::array<int, 3>& d) {
                    return measureGridTrial(v, hf, d, baker, fine, seed);
                });
                c.mapResolution = fine;
            }
            v.gridDims = search.chosen.dims;
            v.spacing.reset();
            value << v.gridDims[0] << "," << v.gridDims[2];
        } else {
            c.setting = "adaptive.tolerance";
            if (v.adaptive.tolerance) c.replaced = nlohmann::json(*v.adaptive.tolerance).dump();
            search = searchAdaptiveTolerance(c.target, [&](double tolerance) {
                return measureAdaptiveTrial(v, hf, tolerance, baker, c.mapResolution, seed);
            });
            v.adaptive.tolerance = search.chosen.tolerance;
            value << std::setprecision(3) << search.chosen.tolerance;
        }
        c.value = value.str();
        c.probes = search.chosen.probes;
        c.bytes = search.chosen.bytes;
        c.spacing = search.chosen.spacing;
        c.p95 = search.chosen.p95;
        c.met = search.met;
        c.capped = search.capped;
        c.trials = search.trials.size();
        if (refinedByError(v.placement)) c.tolerance = search.chosen.tolerance;
        if (v.placement == ProbePlacement::Terrain && c.capped) {
            // Past the cap: what meets the target instead, at a surface volume's cost.
            ProbeVolumeSettings a = v;
            a.placement = ProbePlacement::Surface;
            // Within a box grid's limit: the largest volume an engine allocates for.
            if (!a.adaptive.maxProbes) a.adaptive.maxProbes = kOfferMaxProbes;
            const auto offerStart = Clock::now();
            PlacementSearch as;
            try {
                as = searchAdaptiveTolerance(c.target, [&](double tolerance) {
                    return measureAdaptiveTrial(a, hf, tolerance, baker, c.mapResolution, seed);
                });
            } catch (const PlacementError&) {
                // Its geometry alone is past the budget: no offer.
                as.chosen.p95 = NAN;
            }
            const double offerSeconds = secondsSince(offerStart) / double(std::max<size_t>(as.trials.size(), 1));
            std::ostringstream tol;
            tol << std::setprecision(3) << as.chosen.tolerance;
            std::ostringstream w;
            w << at << ".target_error " << percent(c.target) << " needs more than the " << kMaxTerrainGridProbes
              << " probes a terrain grid may hold: baking the densest allowed, grid_dims " << c.value << " (p95 "
              << percent(c.p95) << ")";
            if (as.met) {
                c.offer = {{"set", {at + ".placement=surface", at + ".target_error=" + nlohmann::json(c.target).dump()}},
                           {"tolerance", as.chosen.tolerance},
                           {"probes", as.chosen.probes},
                           {"bytes", as.chosen.bytes},
                           {"p95", as.chosen.p95},
                           {"estimated_time_s", offerSeconds}};
                w << "; a surface volume meets it: --set " << at << ".placement=surface (tolerance "
                  << tol.str() << ", " << grouped(as.chosen.probes) << " probes, " << grouped(as.chosen.bytes)
                  << " bytes, about " << std::setprecision(2) << offerSeconds << " s, p95 " << percent(as.chosen.p95)
                  << ")";
            } else {
                w << "; no surface volume within " << *a.adaptive.maxProbes << " probes meets it either";
                if (std::isfinite(as.chosen.p95)) w << " (best p95 " << percent(as.chosen.p95) << ")";
                w << ": raise the target or split the terrain into several volumes";
            }
            c.warning = w.str();
        }
        c.seconds = secondsSince(start);
        out[index] = c;
    }
    return out;
}

// Where two volumes' grids overlap, the engine reads the one whose file name sorts first
// (docs/formats.md); the other's probes go unused wherever the first has a probe.
nlohmann::json overlapReport(const std::vector<GltfProbeVolume>& grids) {
    nlohmann::json out = nlohmann::json::array();
    for (size_t a = 0; a < grids.size(); ++a)
        for (size_t b = a + 1; b < grids.size(); ++b) {
            const bool aFirst = grids[a].name + ".shprobe" < grids[b].name + ".shprobe";
            const ShProbeGrid& first = aFirst ? grids[a].grid : grids[b].grid;
            const ShProbeGrid& second = aFirst ? grids[b].grid : grids[a].grid;
            glm::vec3 lo, hi;
            bool overlap = true;
            for (int i = 0; i < 3; ++i) {
                lo[i] = std::max(first.origin[i], second.origin[i]);
                hi[i] = std::min(first.origin[i] + first.spacing * float(first.dims[i]),
                                 second.origin[i] + second.spacing * float(second.dims[i]));
                overlap = overlap && lo[i] < hi[i];
            }
            if (!overlap) continue;
            // Cells of the second grid inside the overlap whose centre falls on a probe of the
            // first: the engine never reads the second grid there.
            size_t shadowed = 0, inside = 0;
            for (uint32_t z = 0; z < second.dims.z; ++z)
                for (uint32_t y = 0; y < second.dims.y; ++y)
                    for (uint32_t x = 0; x < second.dims.x; ++x) {
                        const glm::vec3 c = second.origin + second.spacing *
                                            glm::vec3(float(x) + 0.5f, float(y) + 0.5f, float(z) + 0.5f);
                        if (second.occupancy[second.cellIndex(x, y, z)] < 0) continue;
                        if (glm::any(glm::lessThan(c, lo)) || glm::any(glm::greaterThanEqual(c, hi)))
                            continue;
                        ++inside;
                        const glm::vec3 g = (c - first.origin) / first.spacing;
                        const glm::uvec3 cell = glm::min(glm::uvec3(glm::max(g, glm::vec3(0.0f))),
                                                         first.dims - 1u);
                        shadowed += first.occupancy[first.cellIndex(cell.x, cell.y, cell.z)] >= 0;
                    }
            const std::string firstName = aFirst ? grids[a].name : grids[b].name;
            const std::string secondName = aFirst ? grids[b].name : grids[a].name;
            out.push_back({{"volumes", {firstName, secondName}},
                           {"engine_reads_first", firstName},
                           {"box_min", {lo.x, lo.y, lo.z}},
                           {"box_max", {hi.x, hi.y, hi.z}},
                           {"cells_of_second_with_probe", inside},
                           {"cells_of_second_shadowed_by_first", shadowed}});
        }
    return out;
}

nlohmann::json interpolationReport(const InterpolationError& e, std::optional<double> tolerance,
                                   uint64_t rays) {
    nlohmann::json j = {{"points", e.points},
                        {"uncovered_points", e.uncovered},
                        {"mean", e.mean},
                        {"p95", e.p95},
                        {"max", e.max},
                        {"rays", rays},
                        {"tolerance", tolerance ? nlohmann::json(*tolerance) : nlohmann::json(nullptr)}};
    j["within_tolerance"] = e.withinTolerance ? nlohmann::json(*e.withinTolerance) : nlohmann::json(nullptr);
    return j;
}

nlohmann::json adaptiveReport(const AdaptiveOctree& t, const std::optional<AdaptiveRefinement>& r) {
    nlohmann::json byEdge = nlohmann::json::object();
    std::vector<size_t> counts(size_t(t.levels) + 1, 0);
    for (const OctreeLeaf& l : t.leaves) ++counts[l.level];
    for (size_t l = 0; l < counts.size(); ++l) {
        std::ostringstream edge;
        edge << t.minCell * double(1u << l);
        byEdge[edge.str()] = counts[l];
    }
    nlohmann::json j = {{"tree", t.surface ? "quadtree" : "octree"},
                        {"min_cell_size", t.minCell},
                        {"max_cell_size", t.maxCell},
                        {"surface_band", t.surfaceBand},
                        {"surface_cell_size", t.surfaceCell},
                        {"leaves", t.leaves.size()},
                        {"leaves_by_edge_m", byEdge},
                        {"uniform_grid_probes", t.uniformProbes},
                        {"moved_probes", t.moved},
                        {"borrowed_cells", t.borrowed},
                        {"dropped_cells", t.dropped},
                        {"split_for_inside", t.splitForInside}};
    if (r)
        j["refinement"] = {{"tolerance", r->tolerance},
                           {"rounds", r->rounds},
                           {"leaves_tested", r->leavesTested},
                           {"leaves_split", r->leavesSplit},
                           {"octant_probes_baked", r->octantProbes},
                           {"octant_probes_kept", r->octantProbesKept},
                           {"worst_kept_error", r->worstKeptError},
                           {"budget_reached", r->budgetReached},
                           {"leaves_over_tolerance", r->leavesOverTolerance}};
    else
        j["refinement"] = nullptr;
    return j;
}

constexpr const char* kLpvIniName = "lpv.ini";

// The light propagation volumes for the project's camera, placed as the viewport places them (what
// it starts with): the cascades and where each local light went; a light left out is a warning.
nlohmann::json lpvReport(const SceneDescription& scene, const Heightfield& hf, const BakeLighting& lighting,
                         std::vector<std::string>& warnings) {
    const auto start = std::chrono::steady_clock::now();
    const OrbitCamera camera = OrbitCamera::fromSettings(scene.camera, hf);
    const lpv::Volumes volumes(lpv::resolvedOn(scene.lpv, hf), {&lighting, &scene.lights}, glm::dvec3(camera.lpvEye()),
                               glm::dvec3(camera.lpvViewDirection()));
    nlohmann::json cascades = nlohmann::json::array();
    for (const lpv::Cascade& c : volumes.cascades()) {
        const glm::dvec3 o = c.layout.origin();
        cascades.push_back({{"size", c.layout.size},
                            {"cell_size", c.layout.cellSize},
                            {"origin", {o.x, o.y, o.z}},
                            {"sun_surfels", c.sunSurfels},
                            {"injected_flux", {c.injectedFlux.x, c.injectedFlux.y, c.injectedFlux.z}}});
    }
    nlohmann::json lights = nlohmann::json::array();
    for (const lpv::LightInjection& l : volumes.lightInjections()) {
        lights.push_back({{"light", l.light}, {"cascade", l.cascade}, {"injected", l.injected},
                          {"surfels", l.surfels}, {"reason", l.reason}});
        if (!l.injected && scene.lpv.localLights)
            warnings.push_back("lights[" + std::to_string(l.light) + "]: not injected into the light propagation volumes: " +
                               l.reason + " (for the project's camera)");
    }
    return {{"cascades", cascades},
            {"lights", lights},
            {"time_s", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()}};
}

// Points at which every adaptive volume measures its interpolation error (docs/lighting.md).
constexpr int kInterpolationPoints = 256;

ProbeRays raysOf(const BakeSetup& b, const ProbeVolumeSettings& v) { return volumeRays(b.q, v); }

// Probe rays the bake plans for before it starts: every volume's placed probes and its
// interpolation points (adaptive) at the rays planned (ProbeRays::planned), and its error-map
// points at the least rays. Refinement octants come on top.
uint64_t plannedProbeRays(const BakeSetup& b, const std::vector<ProbeLayout>& layouts,
                          const std::vector<size_t>& mapPoints) {
    uint64_t rays = 0;
    const bool glow = probesSampleGlow(b.lighting);
    auto withGlow = [&](uint64_t n) { return uint64_t(std::llround(probeRaysWithGlow(double(n), glow))); };
    for (size_t vi = 0; vi < b.volumes.size(); ++vi) {
        const ProbeRays r = raysOf(b, *b.volumes[vi]);
        const uint64_t probes = layouts[vi].validCount() + (layouts[vi].octree ? kInterpolationPoints : 0);
        rays += probes * withGlow(uint64_t(r.planned())) + mapPoints[vi] * withGlow(uint64_t(r.rays));
    }
    return rays;
}

uint64_t reflectionSeed() { return splitmix64(0x2EF1EC7ull); }

// The report's `sun`: the image's glow lit as the sun, or where a date and a time put the sun;
// null for a sun set by its angles, which the project states already.
nlohmann::json sunReport(const SceneDescription& scene, const Heightfield& hf, const BakeLighting& lighting) {
    if (sunFromSkyImage(scene)) {
        const ImageSun sun = imageSunOf(lighting);
        return {{"from_sky_image", true},
                {"azimuth_deg", sun.azimuthDeg},
                {"elevation_deg", sun.elevationDeg},
                {"illuminance_lux", sun.illuminanceLux},
                {"angular_radius_deg", sun.angularRadiusDeg},
                {"share_of_sky", sun.shareOfSky}};
    }
    const SunAngles sun = sunAnglesOf(scene, hf);
    if (!sun.place) return nullptr;
    return {{"date", scene.sun.date},
            {"time_h", scene.sun.timeH},
            {"utc_offset_h", sun.place->utcOffsetH},
            {"latitude_deg", sun.place->latitudeDeg},
            {"longitude_deg", sun.place->longitudeDeg},
            {"azimuth_deg", sun.azimuthDeg},
            {"true_azimuth_deg", sun.place->position.azimuthDeg},
            {"elevation_deg", sun.elevationDeg}};
}

// The reflection probes of a bake, baked and encoded for export.
struct ReflectionOutput {
    nlohmann::json report;
    std::vector<std::pair<std::string, std::vector<uint8_t>>> files;
    nlohmann::json gltf;  // TERRALUX_lighting.reflection_probes
    std::vector<std::string> warnings;
};

}  // namespace

ReflectionLighting reflectionLightingOf(const BakeLighting& lighting, const BakeQuality& q, const glm::vec3& groundColor,
                                        const IrradianceCache* sharedCache, int cacheResolution,
                                        std::unique_ptr<IrradianceCache>& own, const BakeControl& control) {
    const IrradianceCache* cache = sharedCache;
    if (!cache) {
        const BakeQuality standard = qualityPreset(QualityPreset::Standard);
        own = std::make_unique<IrradianceCache>(
            lighting, cacheResolution > 0 ? cacheResolution : standard.cacheResolution,
            q.cacheRays > 0 ? q.cacheRays : standard.cacheRays, std::max(q.sunSamples, 1),
            std::max(q.bounces - 1, 0), BakeControl{nullptr, control.cancel});
        cache = own.get();
    }
    return ReflectionLighting{&lighting, cache, std::max(q.bounces, 1), groundRadiance(lighting, groundColor)};
}

namespace {

// The valid probes' values (their standard errors, for the report's statistics).
std::vector<float> ofValidProbes(const std::vector<uint8_t>& valid, const std::vector<float>& values) {
    std::vector<float> out;
    for (size_t i = 0; i < valid.size(); ++i)
        if (valid[i]) out.push_back(values[i]);
    return out;
}

// The coefficients as the .shprobe holds them: radiance projections, or pre-convolved irradiance
// (Â_l L_k) for the irradiance encoding. Last, after every comparison that reads radiance.
void encodeForExport(ShEncoding encoding, std::vector<sh::ShRgb>& sh) {
    if (encoding != ShEncoding::Irradiance) return;
    for (auto& probe : sh)
        for (int k = 0; k < sh::kCoeffCount; ++k) probe.c[size_t(k)] *= sh::kCosineLobe[size_t(sh::bandOf(k))];
}

ReflectionOutput bakeReflections(const BakeSetup& b, const ReflectionProbeSettings& settings,
                                 const ReflectionLayout& layout, const IrradianceCache* sharedCache,
                                 int cacheResolution, bool compareReference, const BakeControl& control) {
    const auto start = Clock::now();
    std::unique_ptr<IrradianceCache> own;
    const ReflectionLighting light =
        reflectionLightingOf(b.lighting, b.q, settings.groundColor, sharedCache, cacheResolution, own, control);

    uint64_t rays = 0;
    ReflectionProbeSet set = bakeReflectionProbes(light, settings, layout, reflectionSeed(), control, &rays);
    ReflectionOutput out;
    nlohmann::json& r = out.report;
    r = {{"probes", set.probes.size()},
         {"grid", {set.dims[0], set.dims[1]}},
         {"origin", {set.origin.x, set.origin.y}},
         {"spacing", {set.spacing.x, set.spacing.y}},
         {"cell_size", {set.cellSize.x, set.cellSize.y}},
         {"fallback_blend_distance", set.blendDistance},
         {"encoding", reflectionEncodingName(settings.encoding)},
         {"resolution", settings.resolution},
         {"rays_per_texel", settings.rayCount},
         {"rays", rays},
         {"bounces", light.bounces}};
    if (compareReference) {
        const auto refStart = Clock::now();
        const ReflectionErrorReport e =
            measureReflectionError(light, settings, set, kReflectionErrorRoughness, reflectionSeed(), control);
        nlohmann::json rows = nlohmann::json::array();
        auto spread = [](const Spread& s) { return nlohmann::json{{"mean", s.mean}, {"p95", s.p95}, {"max", s.max}}; };
        for (const ReflectionError& x : e.byRoughness)
            rows.push_back({{"roughness", x.roughness}, {"faces", spread(x.faces)}, {"cubemap", spread(x.cubemap)}});
        r["reference_error"] = {{"metric", "relative RMS of prefiltered radiance luminance over 256 directions"},
                                {"by_roughness", rows},
                                {"reference_resolution", e.referenceResolution},
                                {"reference_rays", e.rays},
                                {"reference_time_s", secondsSince(refStart)}};
    }
    toEncoding(set, settings.encoding);

    std::vector<uint8_t> rprobe = encodeReflectionProbes(set);
    const ReflectionBoxRecords boxes = encodeBoxRecords(set, settings.simvxSubset);
    r["bytes"] = rprobe.size();
    r["simvx"] = {{"exported_ids", boxes.exported}, {"probes", boxes.total}};
    if (settings.simvxSubset.empty() && boxes.total > boxes.exported.size())
        out.warnings.push_back("reflection_probes: " + std::to_string(boxes.total) +
                               " probes, the simvx box records hold " + std::to_string(kSimvxMaxProbes) +
                               ": exported ids " + [&] {
                                   std::string ids;
                                   for (uint32_t id : boxes.exported) ids += (ids.empty() ? "" : ",") + std::to_string(id);
                                   return ids;
                               }() + " (reflection_probes.simvx_subset chooses them)");
    r["time_s"] = secondsSince(start);
    const std::string dir = "reflection/";
    out.gltf = {{"uri", dir + kReflectionProbeFile},
                {"simvx_desktop_uri", dir + kSimvxDesktopFile},
                {"simvx_wire_uri", dir + kSimvxWireFile},
                {"probes", set.probes.size()},
                {"grid", {set.dims[0], set.dims[1]}},
                {"encoding", r["encoding"]},
                {"face_size", set.faceSize},
                {"mip_count", set.mipCount},
                {"fallback_blend_distance", set.blendDistance},
                {"simvx_probes", boxes.exported.size()},
                {"simvx_ids", boxes.exported}};
    out.files.push_back({kReflectionProbeFile, std::move(rprobe)});
    out.files.push_back({kSimvxDesktopFile, boxes.desktop});
    out.files.push_back({kSimvxWireFile, boxes.wire});
    return out;
}

// What a bake will do, decided before it traces a ray: every volume's placement (an adaptive
// one geometrically, for the progress shares and early errors; it is placed again, with its
// refinement, when it bakes) and its error map's points, the reflection probes (placed first, so
// their settings fail before any work), and the rays and cache resolution they imply. The bake
// and its estimate read the same plan.
struct BakePlan {
    std::vector<ProbeLayout> layouts;  // per enabled volume
    std::vector<size_t> mapPoints;     // per enabled volume: its error map's points
    size_t totalProbes = 0;            // placed probes, every volume's
    size_t totalWork = 0;              // probe bakes progress counts: probes and map points
    std::optional<ReflectionLayout> reflections;
    uint64_t plannedRays = 0;          // plannedProbeRays and the reflection probes' rays
    int cacheResolution = 0;           // cacheResolutionFor those rays
};

BakePlan planBake(const SceneDescription& scene, const BakeSetup& setup) {
    const Heightfield& hf = setup.terrain.heightfield;
    BakePlan p;
    for (const auto* v : setup.volumes) {
        p.layouts.push_back(placeProbes(*v, hf));
        const ProbeLayout& layout = p.layouts.back();
        requireProbes(scene, *v, layout);
        p.mapPoints.push_back(
            errorMapGrid(layout, hf, scene.bake.errorMapResolution, errorMapHeight(*v, layout)).error.size());
        p.totalProbes += layout.positions.size();
        p.totalWork += layout.positions.size() + p.mapPoints.back();
    }
    if (scene.reflectionProbes.enabled) {
        p.reflections = placeReflectionProbes(
            setup.tileWindow ? tileReflectionGrid(scene.reflectionProbes, *setup.tileWindow, hf) : scene.reflectionProbes,
            hf);
        simvxProbes(scene.reflectionProbes.simvxSubset, p.reflections->count());
    }
    p.plannedRays = plannedProbeRays(setup, p.layouts, p.mapPoints);
    if (p.reflections) {
        const ReflectionProbeSettings& rs = scene.reflectionProbes;
        p.plannedRays += uint64_t(p.reflections->count()) * 6 * uint64_t(rs.resolution) * uint64_t(rs.resolution) *
                         uint64_t(rs.rayCount);
    }
    // The cache covers what the tracer holds: a tile's halo too.
    p.cacheResolution = cacheResolutionFor(setup.tracer->heightfield(), setup.q, p.plannedRays);
    return p;
}

// One volume's probes as traced: a grid's (or the reference tracer's), or an adaptive volume's
// after its refinement, with the interpolation error it measured.
struct VolumeTrace {
    ProbeBake bake;
    std::optional<AdaptiveRefinement> refinement;
    std::optional<InterpolationError> interpolation;
    uint64_t interpolationRays = 0;
};

// `phase` names the step for the progress the control reports; an adaptive volume replaces
// `layout` with its refined one.
VolumeTrace traceVolume(const BakeSetup& setup, const IrradianceCache* cache, const ProbeVolumeSettings& v,
                        ProbeLayout& layout, uint64_t seed, const BakeControl& c, std::string& phase) {
    const Heightfield& hf = setup.terrain.heightfield;
    const ProbeRays rays = raysOf(setup, v);
    VolumeTrace t;
    if (!refinedByError(v.placement)) {
        t.bake = setup.referenceMode
                     ? referenceProbes(setup.lighting, setup.q.bounces, layout.positions, layout.valid, rays, seed, c)
                     : bakeProbes(setup.lighting, cache, setup.q.bounces, layout.positions, layout.valid, rays, seed, c);
        return t;
    }
    const ProbeBaker baker = keyedBaker(setup, cache, rays, seed, c);
    AdaptiveBake a = bakeAdaptive(v, hf, baker, [&](int round, size_t leaves) {
        phase = "refining '" + v.name + "' (round " + std::to_string(round) + ", " + std::to_string(leaves) +
                " leaves)";
    });
    layout = std::move(a.layout);
    t.bake = std::move(a.bake);
    t.refinement = a.refinement;
    phase = "interpolation error '" + v.name + "'";
    const ProbeBaker truth = [&](const std::vector<glm::vec3>& p, const std::vector<uint64_t>& k) {
        ProbeBake b = baker(p, k);
        t.interpolationRays += b.rays;
        return b;
    };
    t.interpolation = measureInterpolationError(layout, t.bake.sh, hf, truth, kInterpolationPoints, seed,
                                                v.adaptive.tolerance);
    return t;
}

// What a volume's report says of its probes before any comparison: placement, counts, rays,
// standard error and validity.
nlohmann::json volumeReport(const BakeSetup& setup, const ProbeVolumeSettings& v,
                            const ProbeLayout& layout, const VolumeTrace& t, double seconds) {
    nlohmann::json vr = {
        {"name", v.name},
        {"placement", placementName(v.placement)},
        {"probes", layout.validCount()},
        {"invalid_probes", layout.positions.size() - layout.validCount()},
        {"rays", t.bake.rays},
        {"time_s", seconds},
        {"fallback_blend_distance", layout.fallbackBlendDistance},
        {"moved_probes", layout.octree ? layout.octree->moved : size_t(0)},
        {"borrowed_cells", layout.octree ? layout.octree->borrowed : layout.borrowedCells},
        {"split_for_inside", layout.octree ? layout.octree->splitForInside : size_t(0)},
    };
    if (layout.octree) {
        vr["adaptive"] = adaptiveReport(*layout.octree, t.refinement);
        vr["interpolation_error"] = interpolationReport(*t.interpolation, v.adaptive.tolerance, t.interpolationRays);
    } else {
        vr["probe_grid"] = {layout.probeDims[0], layout.probeDims[1], layout.probeDims[2]};
    }
    std::vector<float> se, below;
    size_t fromBelow = 0;
    for (size_t i = 0; i < layout.valid.size(); ++i)
        if (layout.valid[i]) {
            se.push_back(t.bake.standardError[i]);
            below.push_back(t.bake.fromBelowShare[i]);
            fromBelow += t.bake.fromBelowShare[i] > 0.0f;
        }
    vr["standard_error"] = stats(se);
    const ProbeRays schedule = raysOf(setup, v);
    const RaySpread spread = raySpreadOf(t.bake, layout.valid);
    vr["rays_per_probe"] = {{"min", spread.min}, {"median", spread.median}, {"max", spread.max},
                            {"mean", spread.mean}};
    vr["ray_schedule"] = {{"first", schedule.rays},
                          {"target_standard_error", schedule.adaptive() ? nlohmann::json(schedule.target) : nullptr},
                          {"max", schedule.most()}};
    vr["validity"] = {{"rays_from_below", stats(below)},
                      {"probes_with_rays_from_below", fromBelow},
                      {"lifted_clear_of_surface", layout.liftedForClearance},
                      {"max_lift_m", layout.maxLift}};
    // Probes at or below the water level do not see the water (docs/lighting.md, "Water").
    if (setup.lighting.water) {
        size_t under = 0;
        for (size_t i = 0; i < layout.valid.size(); ++i)
            under += layout.valid[i] && !(layout.positions[i].y > setup.lighting.water->level);
        vr["probes_under_water"] = under;
    }
    return vr;
}

// The probes against the reference path tracer, as written (after deringing). The reference
// traces rounds from the reference preset's rays until each probe's standard error is a third of
// the bake's median (so its own noise adds at most about 5 % to the error measured), at most
// kReferenceMaxRays. A reference bake's probes are the tracer's own: only their standard error speaks.
constexpr int kReferenceMaxRays = 65536;
nlohmann::json referenceReport(const BakeSetup& setup, const ProbeLayout& layout, const ProbeBake& bake,
                               const std::vector<sh::ShRgb>& sh, uint64_t seed, const BakeControl& c,
                               uint64_t& referenceRays) {
    if (setup.referenceMode)
        return {{"mean", nullptr}, {"p95", nullptr}, {"max", nullptr}, {"note", kReferenceNote}};
    std::vector<float> se = ofValidProbes(layout.valid, bake.standardError);
    std::nth_element(se.begin(), se.begin() + ptrdiff_t(se.size() / 2), se.end());
    const float median = se.empty() ? 0.0f : se[se.size() / 2];
    const ProbeRays schedule(qualityPreset(QualityPreset::Reference).rays, median / 3.0f, kReferenceMaxRays);
    const auto start = Clock::now();
    const ProbeBake ref = referenceProbes(setup.lighting, setup.q.bounces, layout.positions, layout.valid, schedule,
                                          seed ^ 0xF00Dull, c);
    referenceRays += ref.rays;
    const ErrorStats err = compareToReference(sh, ref.sh, layout.valid);
    const std::vector<float> refSe = ofValidProbes(layout.valid, ref.standardError);
    const RaySpread spread = raySpreadOf(ref, layout.valid);
    return {{"mean", err.mean},
            {"p95", err.p95},
            {"max", err.max},
            {"reference_standard_error", stats(refSe)},
            {"reference_rays_per_probe",
             {{"min", spread.min}, {"median", spread.median}, {"max", spread.max}, {"mean", spread.mean}}},
            {"reference_path_length",
             setup.q.bounces == 0 ? 0 : referencePathLength(setup.lighting.maxAlbedo())},
            {"reference_rays", ref.rays},
            {"reference_time_s", secondsSince(start)}};
}

// A volume's interpolation-error map (the probes as the engine will read them, against the truth
// at each point), and, where its error is high on a terrain grid without a target, a denser grid
// measured against the same truths.
struct VolumeErrorMap {
    ErrorMapStats stats;
    uint64_t rays = 0;             // the map's own
    double seconds = 0.0;
    std::optional<GridSuggestion> suggestion;
};

VolumeErrorMap measureVolumeErrorMap(const SceneDescription& scene, const BakeSetup& setup, const IrradianceCache* cache,
                                     const ProbeVolumeSettings& v, size_t volumeIndex, const ProbeLayout& layout,
                                     const std::vector<sh::ShRgb>& sh, bool hasTarget, uint64_t seed,
                                     const BakeControl& mc, std::string& phase, ErrorMap& map) {
    const Heightfield& hf = setup.terrain.heightfield;
    // The truths and the trial grids trace the volume's least rays as a fixed count: their
    // sampling error is a small part of an interpolation error worth mapping, and a target's extra
    // rays over every map point would cost more than the bake.
    const ProbeRays rays(raysOf(setup, v).rays);
    const auto start = Clock::now();
    VolumeErrorMap out;
    // The truth gets the same window as the probes, so the map shows interpolation alone.
    const ProbeBaker counted =
        deringedBaker(keyedBaker(setup, cache, rays, seed, mc), scene.bake.deringing, &out.rays);
    std::unordered_map<size_t, sh::ShRgb> truths;
    map = measureErrorMap(layout, sh, hf, counted, scene.bake.errorMapResolution, errorMapHeight(v, layout), seed,
                          &truths);
    out.stats = errorMapStats(map);
    if (errorIsHigh(out.stats) && v.placement == ProbePlacement::Terrain && !hasTarget) {
        phase = "measuring a suggestion for '" + v.name + "'";
        auto measure = [&](const ProbeVolumeSettings& candidate, size_t& probes,
                           uint64_t& suggestionRays) -> std::optional<ErrorMapStats> {
            ProbeLayout trial;
            try {
                trial = placeProbes(candidate, hf);
            } catch (const PlacementError&) {
                return std::nullopt;
            }
            probes = trial.validCount();
            ProbeBake b = setup.referenceMode
                              ? referenceProbes(setup.lighting, setup.q.bounces, trial.positions, trial.valid,
                                                rays.rays, seed, mc)
                              : bakeProbes(setup.lighting, cache, setup.q.bounces, trial.positions, trial.valid,
                                           rays, seed, mc);
            suggestionRays += b.rays;
            if (scene.bake.deringing) sh::deringProbes(b.sh, trial.valid);
            const uint64_t before = out.rays;
            const ErrorMap m = measureErrorMap(trial, b.sh, hf, counted, scene.bake.errorMapResolution,
                                               errorMapHeight(candidate, trial), seed, &truths);
            suggestionRays += out.rays - before;
            out.rays = before;
            return errorMapStats(m);
        };
        // A tile suggests within its share of the limit, so the region's grid it names fits it.
        const int maxProbes = setup.tileWindow ? tileShareOfProbes(kMaxTerrainGridProbes, *setup.tileWindow)
                                               : kMaxTerrainGridProbes;
        out.suggestion = denserGrid(v, volumeIndex, layout, out.stats, measure, maxProbes);
    }
    out.seconds = secondsSince(start);
    return out;
}

// The warnings a bake's volumes earn: probes lifted clear of slopes the tracer cannot resolve,
// and probes that see the terrain from below.
void volumeWarnings(const SceneDescription& scene, const std::vector<const ProbeVolumeSettings*>& volumes,
                    const nlohmann::json& volumeReports, std::vector<std::string>& warnings) {
    // A probe above the surface cannot meet the terrain's underside: one that does sits where the
    // tracer's surface and the placement's disagree (terrain far steeper than any real DEM, as
    // with a large terrain.vertical_scale), and its light is wrong. None does on the shared DEMs.
    for (size_t vi = 0; vi < volumes.size(); ++vi) {
        const nlohmann::json& vr = volumeReports[vi];
        const size_t index = size_t(volumes[vi] - scene.probeVolumes.data());
        const size_t lifted = vr["validity"]["lifted_clear_of_surface"].get<size_t>();
        if (lifted > 0) {
            std::ostringstream w;
            w << "probe_volumes[" << index << "] '" << vr["name"].get<std::string>() << "': " << lifted << " of "
              << vr["probes"].get<size_t>() << " probes stand higher than height_offset (up to "
              << std::fixed << std::setprecision(1) << vr["validity"]["max_lift_m"].get<double>()
              << " m) to clear slopes too steep for the tracer to resolve at " << std::defaultfloat
              << std::setprecision(6) << volumes[vi]->heightOffset << " m";
            if (scene.terrain.verticalScale != 1.0) w << " (terrain.vertical_scale " << scene.terrain.verticalScale << ")";
            warnings.push_back(w.str());
        }
        const size_t below = vr["validity"]["probes_with_rays_from_below"].get<size_t>();
        if (below == 0) continue;
        std::ostringstream w;
        w << "probe_volumes[" << index << "] '" << vr["name"].get<std::string>() << "': " << below << " of "
          << vr["probes"].get<size_t>() << " probes see the terrain from below (up to "
          << percent(vr["validity"]["rays_from_below"]["max"].get<double>())
          << " of their rays), so their light is wrong (debug view 54, probe validity); the surface is steeper than "
             "their clearance";
        if (scene.terrain.verticalScale != 1.0) w << " at terrain.vertical_scale " << scene.terrain.verticalScale;
        w << ": raise probe_volumes[" << index << "].height_offset";
        if (scene.terrain.verticalScale > 1.0) w << " or lower terrain.vertical_scale";
        warnings.push_back(w.str());
    }
}

// bake.target_error's choice judged on the bake's own probes, every volume's, not only the pilot's.
nlohmann::json samplingReport(const SamplingChoice& sampling, const nlohmann::json& volumeReports,
                              std::vector<std::string>& warnings) {
    double baked = 0.0;
    for (const auto& vr : volumeReports) baked = std::max(baked, vr["standard_error"]["p95"].get<double>());
    nlohmann::json t = samplingChoiceReport(sampling);
    t["pilot_met"] = t["met"];
    t["baked_standard_error_p95"] = baked;
    t["met"] = sampling.bounceSearch.met && baked <= sampling.target;
    if (!t["met"].get<bool>()) {
        std::ostringstream w;
        w << "bake.target_error " << percent(sampling.target) << " is not met: ";
        if (!sampling.bounceSearch.met)
            w << "after " << kMaxBounces << " bounces one more still adds " << percent(sampling.bounceSearch.error);
        else
            w << grouped(uint64_t(sampling.rays)) << " rays leave a p95 standard error of " << percent(baked);
        w << "; raise the target"
          << (sampling.rays >= kMaxTargetRays ? "" : " or set bake.rays above " + std::to_string(sampling.rays));
        warnings.push_back(w.str());
    }
    return t;
}

// The .shprobe files and their sidecars, the scene when export.gltf is on, and the report: staged
// together and committed with rollback, so a failed export leaves the earlier files, and an
// earlier bake's files that this one does not write go. Fills the report's file list and time.
std::vector<std::filesystem::path> writeBake(const Project& project, const BakeSetup& setup, std::vector<GltfProbeVolume> grids,
                                   std::vector<GltfScenario> scenarios, const nlohmann::json& bakeInfo, std::optional<ReflectionOutput>& reflections,
                                   BakeOutcome& out, Clock::time_point start) {
    const SceneDescription& scene = project.scene;
    const BakeLighting& lighting = setup.lighting;
    GltfSceneInput in;
    in.heightfield = &setup.terrain.heightfield;
    in.surroundings = setup.tracedTerrain.get();
    const Heightfield& whole = setup.region ? *setup.region : setup.terrain.heightfield;
    in.albedo = scene.terrain.albedo;
    in.albedoTexture = lighting.surface.get();
    in.roughness = float(scene.terrain.roughness);
    in.verticalScale = scene.terrain.verticalScale;
    in.volumes = std::move(grids);
    in.bake = bakeInfo;
    in.lighting = lightingExtension(project, whole, lighting);
    in.scenarios = std::move(scenarios);
    in.defaultLighting = {{"sun", in.lighting.at("sun")}, {"sky", in.lighting.at("sky")}};
    if (reflections) {
        for (const auto& [k, v] : reflections->gltf.items()) in.lighting["reflection_probes"][k] = v;
        in.reflectionFiles = std::move(reflections->files);
    }
    if (lighting.water) in.water = GltfWater{lighting.water->level, scene.water.color, float(scene.water.roughness)};
    in.lights = scene.lights;
    // lpv.ini is the bake's whenever the LPV is on; a bake with it off removes an earlier one.
    in.ownedFiles.push_back(kLpvIniName);
    if (scene.lpv.enabled)
        in.extraFiles.push_back({kLpvIniName, lpvIni(lpv::resolvedOn(scene.lpv, whole))});
    in.generatorVersion = TERRALUX_VERSION;
    in.scene = scene.exportSettings.gltf;
    // The report lists every file of the bake, itself included, in the order written.
    in.extraFiles.push_back({"bake_report.json", ""});
    out.report["files"] = exportedFileNames(in);
    out.report["time_s"] = secondsSince(start);
    in.extraFiles.back().second = out.report.dump(2) + "\n";
    return exportGltfScene(out.outDir, in).files;
}

}  // namespace

// The bake's stages: prepare (terrain, lighting, quality), the targets, the plan, the irradiance
// cache, then per volume its probes (traceVolume), their reference comparison, their error map
// (measureVolumeErrorMap) and encoding; the reflection probes; the report and its warnings; and
// the staged write (writeBake).
BakeOutcome runBake(const BakeRequest& original, const BakeProgress& progress,
                    const std::atomic<bool>* cancel) {
    const auto start = Clock::now();
    // The project as baked: target_error rewrites the volumes' grid_dims or tolerance here, while
    // bake_report.json's inputs stay the project's own (so the bake is current for it).
    BakeRequest request = original;
    const Project& project = request.project;
    const SceneDescription& scene = project.scene;
    const int threads = request.threads > 0 ? request.threads : tbb::info::default_concurrency();
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));

    auto report = [&](const std::string& phase, double f) {
        if (progress) progress(phase, std::clamp(f, 0.0, 1.0));
    };
    auto cancelled = [&] { return cancel && cancel->load(); };

    BakeSetup setup;
    prepare(project, setup, report, cancelled, request.tile);
    if (setup.tileWindow) {
        // Placed from here on: each volume over the tile's share (setup.volumes point into it).
        scaleSceneToTile(request.project.scene, *setup.tileWindow);
    }
    const std::optional<SamplingChoice> sampling =
        chooseSampling(request.project.scene, setup, [&](const std::string& p) { report(p, 0.02); });
    const std::map<size_t, TargetChoice> targets =
        chooseTargets(request.project.scene, setup, [&](const std::string& p) { report(p, 0.02); });
    if (cancelled()) throw BakeCancelled();
    const Heightfield& hf = setup.terrain.heightfield;
    const BakeLighting& lighting = setup.lighting;
    const BakeQuality& q = setup.q;
    const bool referenceMode = setup.referenceMode;
    const auto& volumes = setup.volumes;
    BakePlan plan = planBake(scene, setup);

    // One bake writes into a folder at a time, from here to its end, so two never mix their files.
    // Taken once the inputs are checked, so that an input error is reported as such, and before
    // any work. What a killed bake left there (its staging folder, temporaries) goes first.
    const OutputFolderLock folderLock(project.outDir());
    removeStaleTemporaries(project.outDir());

    // Phase weights for one progress bar: cache, probes, reference.
    double cacheShare = (!referenceMode && q.bounces > 0) ? 0.35 : 0.0;
    const double refShare = request.compareReference && !referenceMode && !volumes.empty() ? 0.45 : 0.0;
    const double reflectionShare = !plan.reflections ? 0.0 : volumes.empty() ? 0.95 - cacheShare : 0.3;
    double probeShare = 0.97 - 0.02 - cacheShare - refShare - reflectionShare;
    // Each lighting scenario costs about a cache and the probes again (no map, no reference).
    const double lightings = double(1 + scene.scenarios.size());
    const double scenarioShare = (cacheShare + probeShare) * (1.0 - 1.0 / lightings);
    cacheShare /= lightings;
    probeShare /= lightings;
    double base = 0.02;

    std::unique_ptr<IrradianceCache> cache;
    const auto cacheStart = Clock::now();
    if (!referenceMode && q.bounces > 0) {
        BakeControl c{[&](double f) { report("irradiance cache", base + cacheShare * f); }, cancel};
        cache = std::make_unique<IrradianceCache>(lighting, plan.cacheResolution, q.cacheRays,
                                                  q.sunSamples, q.bounces - 1, c);
    }
    const double cacheSeconds = secondsSince(cacheStart);
    const uint64_t cacheRays = cache ? cache->rays() : 0;
    base += cacheShare;

    nlohmann::json volumeReports = nlohmann::json::array();
    std::vector<GltfProbeVolume> grids;
    uint64_t totalRays = 0, referenceRays = 0;
    size_t done = 0, doneWork = 0;
    std::map<size_t, GridSuggestion> measuredSuggestions;
    for (size_t vi = 0; vi < volumes.size(); ++vi) {
        const ProbeVolumeSettings& v = *volumes[vi];
        const size_t volumeIndex = size_t(volumes[vi] - scene.probeVolumes.data());
        ProbeLayout& layout = plan.layouts[vi];
        const auto volumeStart = Clock::now();
        const double share = plan.totalProbes ? double(layout.positions.size()) / double(plan.totalProbes) : 1.0;
        const uint64_t seed = volumeSeed(vi);
        std::string phase = "probes '" + v.name + "'";
        const double probeWork = double(layout.positions.size()), mapWork = double(plan.mapPoints[vi]);
        const double totalWork = double(std::max<size_t>(plan.totalWork, 1));
        const BakeControl c{[&](double f) {
                                report(phase, base + probeShare * (double(doneWork) + f * probeWork) / totalWork);
                            },
                            cancel};
        VolumeTrace trace = traceVolume(setup, cache.get(), v, layout, seed, c, phase);
        ProbeBake& bake = trace.bake;
        totalRays += bake.rays + trace.interpolationRays;
        nlohmann::json vr = volumeReport(setup, v, layout, trace, secondsSince(volumeStart));
        if (targets.count(volumeIndex)) vr["target"] = targetChoiceReport(targets.at(volumeIndex));

        // Radiance projections, optionally windowed so irradiance is never negative. Before the
        // reference comparison, so that measures the probes as they are written.
        const sh::DeringSummary dering =
            scene.bake.deringing ? sh::deringProbes(bake.sh, layout.valid) : sh::DeringSummary{};

        if (request.compareReference) {
            const BakeControl rc{[&](double f) {
                                     report("reference '" + v.name + "'",
                                            base + probeShare +
                                                refShare * (double(done) / double(plan.totalProbes) + share * f));
                                 },
                                 cancel};
            vr["reference_error"] = referenceReport(setup, layout, bake, bake.sh, seed, rc, referenceRays);
        }

        // The interpolation-error map of the probes as the engine will read them (the
        // interpolation-error debug view).
        ProbeDiagnostics diagnostics = describeProbes(layout, bake.standardError);
        if (scene.bake.errorMapResolution > 0) {
            phase = "error map '" + v.name + "'";
            const BakeControl mc{[&](double f) {
                                     report(phase, base + probeShare * (double(doneWork) + probeWork + f * mapWork) /
                                                              totalWork);
                                 },
                                 cancel};
            const VolumeErrorMap m = measureVolumeErrorMap(scene, setup, cache.get(), v, volumeIndex, layout, bake.sh,
                                                           targets.count(volumeIndex) > 0, seed, mc, phase,
                                                           diagnostics.errorMap);
            if (m.suggestion) {
                totalRays += m.suggestion->rays;
                measuredSuggestions[volumeIndex] = *m.suggestion;
            }
            totalRays += m.rays;
            const ErrorMapStats& ms = m.stats;
            vr["error_map"] = {{"size", {diagnostics.errorMap.nx, diagnostics.errorMap.nz}},
                               {"step_m", diagnostics.errorMap.step},
                               {"height_m", diagnostics.errorMap.height},
                               {"points", ms.points},
                               {"uncovered", ms.uncovered},
                               {"mean", ms.mean},
                               {"p95", ms.p95},
                               {"max", ms.max},
                               {"rays", m.rays},
                               {"time_s", m.seconds}};
            // The target is judged on this map, the bake's own, not the search's coarser one.
            if (targets.count(volumeIndex) && ms.points > 0) {
                TargetChoice judged = targets.at(volumeIndex);
                judged.bakeP95 = ms.p95;
                vr["target"] = targetChoiceReport(judged);
            }
        }

        encodeForExport(scene.bake.encoding, bake.sh);
        if (scene.bake.deringing)
            vr["deringing"] = {{"window", "lanczos-sigma"},
                               {"probes_windowed", dering.windowed},
                               {"strongest_width", std::isfinite(dering.strongest) ? nlohmann::json(dering.strongest)
                                                                                   : nlohmann::json(nullptr)}};
        ShProbeGrid grid = toGrid(layout, bake.sh, scene.exportSettings);
        vr["bytes"] = grid.fileSize();
        vr["grid"] = {{"dims", {grid.dims.x, grid.dims.y, grid.dims.z}},
                      {"origin", {grid.origin.x, grid.origin.y, grid.origin.z}},
                      {"spacing", grid.spacing}};
        volumeReports.push_back(vr);
        std::string sidecar = encodeProbeDiagnostics(diagnostics, v.name, grid);
        grids.push_back({v.name, std::move(grid), std::move(sidecar)});
        done += layout.positions.size();
        doneWork += layout.positions.size() + plan.mapPoints[vi];
    }
    if (cancelled()) throw BakeCancelled();

    // Lighting scenarios: the layouts just baked, lit by each scenario's sun and sky, with an
    // irradiance cache of its own; written as the default's are (deringing, encoding).
    std::vector<GltfScenario> scenarioGrids;
    nlohmann::json scenarioReports = nlohmann::json::array();
    std::vector<std::string> scenarioWarnings;
    const double scenarioBase = 0.02 + (cacheShare + probeShare) + refShare;
    for (size_t si = 0; si < scene.scenarios.size(); ++si) {
        const std::string& name = scene.scenarios[si].name;
        const auto scenarioStart = Clock::now();
        const double n = double(scene.scenarios.size());
        auto scenarioProgress = [&](double f) {
            report("scenario '" + name + "'", scenarioBase + scenarioShare * (double(si) + f) / n);
        };
        Project litProject = project;
        litProject.scene = scenarioScene(scene, name);
        const BakeLighting lit = scenarioLightingOf(project, name, hf, lighting);
        imageSunWarnings(litProject.scene, lit, "scenarios[" + std::to_string(si) + "].", scenarioWarnings);
        std::unique_ptr<IrradianceCache> litCache;
        if (!referenceMode && q.bounces > 0)
            litCache = std::make_unique<IrradianceCache>(
                lit, plan.cacheResolution, q.cacheRays, q.sunSamples, q.bounces - 1,
                BakeControl{[&](double f) { scenarioProgress(0.3 * f); }, cancel});
        const nlohmann::json ext = lightingExtension(litProject, hf, lit);
        GltfScenario out{name, {}, {{"sun", ext.at("sun")}, {"sky", ext.at("sky")}}};
        nlohmann::json sr = {{"name", name}, {"cache_rays", litCache ? litCache->rays() : 0}};
        if (nlohmann::json sun = sunReport(litProject.scene, hf, lit); !sun.is_null()) sr["sun"] = std::move(sun);
        uint64_t rays = 0;
        for (size_t vi = 0; vi < volumes.size(); ++vi) {
            const ProbeVolumeSettings& v = *volumes[vi];
            const ProbeLayout& layout = plan.layouts[vi];
            const BakeControl c{[&](double f) {
                                    scenarioProgress(0.3 + 0.7 * (double(vi) + f) / double(volumes.size()));
                                },
                                cancel};
            ProbeBake b = referenceMode ? referenceProbes(lit, q.bounces, layout.positions, layout.valid,
                                                          raysOf(setup, v), volumeSeed(vi), c)
                                        : bakeProbes(lit, litCache.get(), q.bounces, layout.positions, layout.valid,
                                                     raysOf(setup, v), volumeSeed(vi), c);
            rays += b.rays;
            if (scene.bake.deringing) (void)sh::deringProbes(b.sh, layout.valid);
            encodeForExport(scene.bake.encoding, b.sh);
            sr["volumes"].push_back({{"name", v.name},
                                     {"rays", b.rays},
                                     {"standard_error", stats(ofValidProbes(layout.valid, b.standardError))}});
            out.volumes.push_back({v.name, toGrid(layout, b.sh, scene.exportSettings), ""});
        }
        if (cancelled()) throw BakeCancelled();
        sr["probe_rays"] = rays;
        sr["file_stem"] = "scenarios/<volume>." + name + ".shprobe";
        sr["time_s"] = secondsSince(scenarioStart);
        totalRays += rays;
        scenarioReports.push_back(std::move(sr));
        scenarioGrids.push_back(std::move(out));
    }

    std::optional<ReflectionOutput> reflections;
    if (plan.reflections) {
        const BakeControl rc{[&](double f) { report("reflection probes", 0.97 - reflectionShare * (1.0 - f)); },
                             cancel};
        reflections = bakeReflections(setup, scene.reflectionProbes, *plan.reflections, cache.get(),
                                      plan.cacheResolution, request.compareReference, rc);
    }

    nlohmann::json bakeInfo = {
        {"shEncoding", scene.bake.encoding == ShEncoding::Irradiance ? "irradiance" : "radiance"},
        {"shConvention", "real SH L2, k = l(l+1)+m, no Condon-Shortley phase, engine frame Y up"},
        {"qualityPreset", qualityName(scene.bake.quality)},
        {"rays", q.rays},
        {"bounces", q.bounces},
        {"deringing", scene.bake.deringing},
    };
    // High interpolation error: say what would lower it, with the dry run's estimates.
    for (size_t vi = 0; vi < volumes.size(); ++vi) {
        nlohmann::json& vr = volumeReports[vi];
        if (!vr.contains("error_map") || vr["error_map"]["points"].get<size_t>() == 0) continue;
        // A volume with a target_error has its placement from the target.
        if (vr.contains("target")) continue;
        const size_t index = size_t(volumes[vi] - scene.probeVolumes.data());
        const auto g = measuredSuggestions.find(index);
        vr["suggestions"] = suggestions(request, index,
                                        g == measuredSuggestions.end() ? std::nullopt
                                                                       : std::optional<GridSuggestion>(g->second),
                                        setup, threads);
    }
    nlohmann::json errorEstimate = nlohmann::json::object();
    for (const auto& vr : volumeReports) {
        nlohmann::json e = {{"standardError", vr["standard_error"]}};
        if (vr.contains("reference_error")) e["referenceError"] = vr["reference_error"];
        errorEstimate[vr["name"].get<std::string>()] = e;
    }
    bakeInfo["errorEstimate"] = errorEstimate;

    report("writing", 0.97);
    BakeOutcome out;
    out.outDir = project.outDir();
    std::filesystem::create_directories(out.outDir);
    out.report = {
        {"generator", std::string("Terralux ") + TERRALUX_VERSION},
        {"terrain",
         {{"source", setup.terrain.source.path},
          {"grid", {hf.width(), hf.depth()}},
          {"cell_size_m", {hf.cellSizeX(), hf.cellSizeZ()}},
          {"height_range_m", {hf.minHeight(), hf.maxHeight()}},
          {"nodata_cells", hf.nodataCount()},
          {"crs", hf.geo.crsName},
          {"epsg", hf.geo.epsg},
          {"origin", {{"easting", hf.geo.easting}, {"northing", hf.geo.northing}}}}},
        {"quality",
         {{"preset", qualityName(scene.bake.quality)},
          {"rays", q.rays},
          {"target_standard_error", q.targetError > 0.0f ? nlohmann::json(q.targetError) : nullptr},
          {"max_rays", q.probeRays().most()},
          {"bounces", q.bounces},
          {"cache_resolution", cache ? plan.cacheResolution : 0},
          {"cache_points", cache ? size_t(cache->pointsX()) * size_t(cache->pointsZ()) : size_t(0)},
          {"cache_rays", cache ? q.cacheRays : 0},
          {"cache_time_s", cacheSeconds},
          {"final_gather", cache && cache->gathersAtHits()}}},
        {"sh_encoding", scene.bake.encoding == ShEncoding::Irradiance ? "irradiance" : "radiance"},
        {"inputs", bakeInputs(original.project)},
        {"threads", threads},
        {"tracer_kernel", HeightfieldTracer::autoKernelName()},
        {"sky_glow", {{"share", lighting.sky.glowShare()}, {"probes_sample_it", probesSampleGlow(lighting)}}},
        {"rays", totalRays + cacheRays + referenceRays},
        {"probe_rays", totalRays},
        {"cache_rays", cacheRays},
        {"reference_rays", referenceRays},
        {"time_s", secondsSince(start)},
        {"volumes", volumeReports},
        {"overlaps", overlapReport(grids)},
    };
    if (setup.tileWindow) out.report["tile"] = setup.tileReport;
    if (!scenarioReports.empty()) {
        uint64_t cacheRaysAll = 0;
        for (const auto& sr : scenarioReports) cacheRaysAll += sr["cache_rays"].get<uint64_t>();
        out.report["scenarios"] = scenarioReports;
        out.report["cache_rays"] = cacheRays + cacheRaysAll;
        out.report["rays"] = out.report["rays"].get<uint64_t>() + cacheRaysAll;
    }
    if (reflections) {
        const nlohmann::json& rr = reflections->report;
        const uint64_t reflectionRays =
            rr["rays"].get<uint64_t>() + (rr.contains("reference_error") ? rr["reference_error"]["reference_rays"].get<uint64_t>() : 0);
        out.report["reflection_rays"] = reflectionRays;
        out.report["rays"] = out.report["rays"].get<uint64_t>() + reflectionRays;
        out.report["reflection_probes"] = rr;
        out.warnings = reflections->warnings;
    }
    if (scene.lpv.enabled) out.report["lpv"] = lpvReport(scene, hf, lighting, out.warnings);
    // Where the sun the bake lit with stands, when the project does not say it in angles.
    if (nlohmann::json sun = sunReport(scene, hf, lighting); !sun.is_null()) out.report["sun"] = std::move(sun);
    imageSunWarnings(scene, lighting, "", out.warnings);
    out.warnings.insert(out.warnings.end(), scenarioWarnings.begin(), scenarioWarnings.end());
    if (scene.water.enabled && !lighting.water)
        out.warnings.push_back("water.level auto: " + water::autoLevel(hf).summary +
                               "; no water is baked or exported; set water.level to place it");
    for (const auto& [index, c] : targets)
        if (!c.warning.empty()) out.warnings.push_back(c.warning);
    volumeWarnings(scene, volumes, volumeReports, out.warnings);
    if (sampling) out.report["sampling_target"] = samplingReport(*sampling, volumeReports, out.warnings);
    out.report["warnings"] = out.warnings;
    out.files = writeBake(project, setup, std::move(grids), std::move(scenarioGrids), bakeInfo, reflections, out, start);
    report("done", 1.0);
    return out;
}

namespace {

nlohmann::json fileIdentity(const std::filesystem::path& path) {
    std::error_code ec;
    nlohmann::json id = {{"path", path.lexically_normal().generic_string()}};
    const auto size = std::filesystem::file_size(path, ec);
    if (!ec) id["bytes"] = size;
    if (const std::optional<int64_t> ns = modifiedUnixNanoseconds(path)) id["modified_ns"] = *ns;
    return id;
}

// "a.b[2].c" -> value, for every leaf.
void flatten(const nlohmann::json& v, const std::string& path, std::map<std::string, nlohmann::json>& out) {
    if (v.is_object() && !v.empty()) {
        for (const auto& [k, x] : v.items()) flatten(x, path.empty() ? k : path + "." + k, out);
    } else if (v.is_array() && !v.empty() && (v[0].is_object())) {
        for (size_t i = 0; i < v.size(); ++i) flatten(v[i], path + "[" + std::to_string(i) + "]", out);
    } else {
        out[path] = v;
    }
}

}  // namespace

nlohmann::json samplingChoiceReport(const SamplingChoice& c) {
    auto trials = [](const SamplingSearch& s, const char* key) {
        nlohmann::json out = nlohmann::json::array();
        for (const auto& t : s.trials) out.push_back({{key, t.value}, {"p95", t.error}});
        return out;
    };
    return {{"target", c.target},
            {"rays", c.rays},
            {"bounces", c.bounces},
            {"replaced", c.replaced},
            {"pilot_probes", c.pilotProbes},
            {"bounce_trial_rays", kBounceTrialRays},
            {"standard_error_p95", c.raySearch.error},
            {"next_bounce_change_p95", c.bounceSearch.error},
            {"met", c.met},
            {"ray_trials", trials(c.raySearch, "rays")},
            {"bounce_trials", trials(c.bounceSearch, "bounces")},
            {"seconds", c.seconds},
            {"summary", c.summary}};
}

std::string targetSummary(const TargetChoice& c) {
    std::ostringstream sum;
    sum << (c.tolerance ? "min cell " : "spacing ") << std::lround(c.spacing) << " m";
    if (c.tolerance) sum << ", tolerance " << percent(*c.tolerance);
    sum << ", " << grouped(c.probes) << " probes, p95 " << percent(c.bakeP95.value_or(c.p95));
    return sum.str();
}

nlohmann::json targetChoiceReport(const TargetChoice& c) {
    nlohmann::json j = {{"target", c.target},
            {"setting", c.setting},
            {"value", c.value},
            {"replaced", c.replaced.empty() ? nlohmann::json(nullptr) : nlohmann::json(c.replaced)},
            {"probes", c.probes},
            {"bytes", c.bytes},
            {"spacing_m", c.spacing},
            {"search_p95", c.p95},
            {"search_map_resolution", c.mapResolution},
            {"met", c.bakeP95 ? *c.bakeP95 <= c.target : c.met},
            {"capped", c.capped},
            {"trials", c.trials},
            {"time_s", c.seconds},
            {"summary", targetSummary(c)},
            {"offer", c.offer}};
    if (c.bakeP95) j["p95"] = *c.bakeP95;
    return j;
}

nlohmann::json bakeInputs(const Project& project) {
    // The parameter table says which rows a bake reads (BakeUse); a file counts by what it
    // resolves to, not by how the project spells its path.
    return bakeReadSettings(project.scene, [&](const ParameterSpec&, const std::string& value) {
        return fileIdentity(project.resolve(value));
    });
}

std::vector<std::string> bakeInputDifferences(const nlohmann::json& baked, const nlohmann::json& now) {
    std::map<std::string, nlohmann::json> a, b;
    flatten(baked, "", a);
    flatten(now, "", b);
    std::vector<std::string> out;
    auto name = [](const std::string& path) {
        // "settings.sun.elevation_deg" is the project's "sun.elevation_deg".
        return path.rfind("settings.", 0) == 0 ? path.substr(9) : path;
    };
    for (const auto& [path, v] : b) {
        const auto it = a.find(path);
        if (it == a.end()) out.push_back(name(path) + ": not in the bake, now " + v.dump());
        else if (it->second != v) out.push_back(name(path) + ": baked " + it->second.dump() + ", now " + v.dump());
    }
    for (const auto& [path, v] : a)
        if (!b.count(path)) out.push_back(name(path) + ": baked " + v.dump() + ", not in the project");
    return out;
}

BakeEstimate estimateBake(const BakeRequest& request) {
    const int threads = request.threads > 0 ? request.threads : tbb::info::default_concurrency();
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    BakeSetup setup;
    BakeRequest chosen = request;
    prepare(chosen.project, setup, [](const std::string&, double) {}, [] { return false; }, chosen.tile, false);
    if (setup.tileWindow) scaleSceneToTile(chosen.project.scene, *setup.tileWindow);
    const std::optional<SamplingChoice> sampling = chooseSampling(chosen.project.scene, setup, [](const std::string&) {});
    const std::map<size_t, TargetChoice> targets = chooseTargets(chosen.project.scene, setup, [](const std::string&) {});
    BakeEstimate e = estimateWith(chosen, setup, threads, true);
    e.sampling = sampling;
    for (auto& ve : e.volumes)
        for (const auto& [index, c] : targets)
            if (chosen.project.scene.probeVolumes[index].name == ve.name) {
                ve.target = c;
                if (!c.warning.empty()) e.warnings.push_back(c.warning);
            }
    return e;
}

Project resolveTargets(const Project& project, int threads) {
    bool any = bool(project.scene.bake.targetError);
    for (const auto& v : project.scene.probeVolumes) any = any || (v.enabled && v.targetError);
    if (!any) return project;
    threads = threads > 0 ? threads : tbb::info::default_concurrency();
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    Project resolved = project;
    BakeSetup setup;
    prepare(resolved, setup, [](const std::string&, double) {}, [] { return false; });
    if (chooseSampling(resolved.scene, setup, [](const std::string&) {})) {
        resolved.scene.bake.rays = setup.q.rays;
        resolved.scene.bake.bounces = setup.q.bounces;
        resolved.scene.bake.targetError.reset();
    }
    chooseTargets(resolved.scene, setup, [](const std::string&) {});
    for (auto& v : resolved.scene.probeVolumes) v.targetError.reset();
    return resolved;
}

namespace {

// A terrain grid's error map as the bake will measure it: the grid's probes and its map, baked as
// the bake bakes them (same rays, seeds, cache, window and points). Whether it is high
// (errorIsHigh), and so whether the bake measures a suggestion, is then the bake's own answer.
struct PlannedMap {
    ErrorMapStats stats;
    double secondsPerPoint = 0.0;  // the map's truths, interpolation and all, per point
};
PlannedMap plannedErrorMap(const BakeSetup& setup, const IrradianceCache* cache, const BakeSettings& bake,
                           const ProbeVolumeSettings& v, const ProbeLayout& L, uint64_t seed) {
    ProbeBake b = bakeProbes(setup.lighting, cache, setup.q.bounces, L.positions, L.valid, raysOf(setup, v), seed, BakeControl{});
    if (bake.deringing) sh::deringProbes(b.sh, L.valid);
    const ProbeBaker truth =
        deringedBaker(keyedBaker(setup, cache, ProbeRays(raysOf(setup, v).rays), seed, BakeControl{}), bake.deringing);
    const auto start = Clock::now();
    const ErrorMap m = measureErrorMap(L, b.sh, setup.terrain.heightfield, truth, bake.errorMapResolution,
                                       errorMapHeight(v, L), seed);
    PlannedMap out;
    out.stats = errorMapStats(m);
    out.secondsPerPoint = secondsSince(start) / double(std::max<size_t>(m.error.size(), 1));
    return out;
}

BakeEstimate estimateWith(const BakeRequest& request, BakeSetup& setup, int threads, bool full) {
    const Project& project = request.project;
    const SceneDescription& scene = project.scene;
    const Heightfield& hf = setup.terrain.heightfield;
    const BakeQuality& q = setup.q;

    BakeEstimate e;
    e.threads = threads;
    e.quality = qualityName(scene.bake.quality);
    e.rays = q.rays;
    e.raysText = raysDescription(q.probeRays());
    e.bounces = q.bounces;
    e.lpvIni = scene.lpv.enabled;
    e.lights = scene.lights.size();

    // The bake's own plan: its placements, error-map points, reflection probes and cache size.
    const BakePlan plan = planBake(scene, setup);
    std::vector<glm::vec3> all;
    for (const ProbeLayout& layout : plan.layouts)
        for (size_t i = 0; i < layout.positions.size(); ++i)
            if (layout.valid[i]) all.push_back(layout.positions[i]);

    // The cache: in full, the bake's own, built and timed (the map below then reads what the
    // bake's will); otherwise a small one with the real ray counts, scaled by the point count.
    std::unique_ptr<IrradianceCache> cache;
    if (!setup.referenceMode && q.bounces > 0) {
        constexpr int kCalibrationResolution = 16;
        const auto t = Clock::now();
        cache = std::make_unique<IrradianceCache>(setup.lighting, full ? plan.cacheResolution : kCalibrationResolution,
                                                  q.cacheRays, q.sunSamples, q.bounces - 1, BakeControl{});
        const std::array<int, 2> points = IrradianceCache::gridPoints(setup.tracer->heightfield(), plan.cacheResolution);
        e.cacheSeconds = secondsSince(t) * double(points[0]) * double(points[1]) /
                         double(cache->pointsX() * cache->pointsZ());
    }


    // Probes: a few of the volumes' own, spread over them, baked as the bake would; with a target,
    // the rays they traced stand for every probe's.
    double secondsPerProbeRay = 0.0, meanRays = double(q.rays);
    if (!all.empty()) {
        const size_t n = std::min(all.size(), std::max<size_t>(64, 16 * size_t(threads)));
        std::vector<glm::vec3> sample(n);
        for (size_t i = 0; i < n; ++i) sample[i] = all[i * all.size() / n];
        const std::vector<uint8_t> valid(n, 1);
        const auto t = Clock::now();
        const ProbeBake b = setup.referenceMode
                                ? referenceProbes(setup.lighting, q.bounces, sample, valid, q.probeRays(), 1,
                                                  BakeControl{})
                                : bakeProbes(setup.lighting, cache.get(), q.bounces, sample, valid, q.probeRays(), 1,
                                             BakeControl{});
        meanRays = raySpreadOf(b, valid).mean;
        e.meanRays = meanRays;
        secondsPerProbeRay = secondsSince(t) / (double(n) * meanRays);
        e.probeRaysPerSecond = secondsPerProbeRay > 0 ? 1.0 / secondsPerProbeRay : 0.0;
        // The same probes under each scenario's sun and sky (the default's cache carries the
        // bounces: the rays follow the direct light's variance).
        for (const LightingScenario& sc : scene.scenarios) {
            const BakeLighting lit = scenarioLightingOf(request.project, sc.name, hf, setup.lighting);
            const ProbeBake sb = setup.referenceMode
                                     ? referenceProbes(lit, q.bounces, sample, valid, q.probeRays(), 1, BakeControl{})
                                     : bakeProbes(lit, cache.get(), q.bounces, sample, valid, q.probeRays(), 1, BakeControl{});
            e.scenarios.push_back({sc.name, raySpreadOf(sb, valid).mean, 0.0});
        }
    }

    // Loading is what this estimate's own setup took; writing, the glTF mesh (whose buffers grow
    // with the vertices) exported from a flat terrain of kWriteSide² samples into a scratch
    // folder, scaled by the vertex count.
    e.loadSeconds = setup.prepareSeconds;
    if (scene.exportSettings.gltf && hf.width() > 1 && hf.depth() > 1) {
        constexpr int kWriteSide = 256;
        const Heightfield small(kWriteSide, kWriteSide, hf.cellSizeX(), hf.cellSizeZ(),
                                std::vector<float>(size_t(kWriteSide) * kWriteSide, 0.0f));
        GltfSceneInput in;
        in.heightfield = &small;
        in.generatorVersion = TERRALUX_VERSION;
        // An albedo texture is encoded as PNG: a block of its own texels, so it compresses alike.
        SurfaceAlbedo texture;
        double scale = double(hf.width()) * double(hf.depth());
        if (const SurfaceAlbedo* a = setup.lighting.surface.get(); a && !a->empty()) {
            texture.resize(kWriteSide, kWriteSide);
            for (int r = 0; r < kWriteSide; ++r)
                for (int c = 0; c < kWriteSide; ++c) {
                    const size_t from = 3 * (size_t(std::min(r, a->height - 1)) * a->width + size_t(std::min(c, a->width - 1)));
                    std::copy_n(a->srgb.begin() + std::ptrdiff_t(from), 3, texture.srgb.begin() + std::ptrdiff_t(3 * (size_t(r) * kWriteSide + c)));
                }
            in.albedoTexture = &texture;
            scale = std::max(scale, double(a->texels()));
        }
        const std::filesystem::path scratch = std::filesystem::temp_directory_path() /
                                              ("terralux-estimate-" + std::to_string(splitmix64(uint64_t(Clock::now().time_since_epoch().count()))));
        const auto t = Clock::now();
        try {
            exportGltfScene(scratch, in);
            e.writeSeconds = secondsSince(t) * scale / double(kWriteSide * kWriteSide);
        } catch (const std::exception&) {
            // No scratch space: the estimate goes without writing.
        }
        std::error_code ignored;
        std::filesystem::remove_all(scratch, ignored);
    }
    e.seconds = e.secondsMax = e.cacheSeconds + e.loadSeconds + e.writeSeconds;
    if (plan.reflections) {
        const ReflectionProbeSettings& rs = scene.reflectionProbes;
        const ReflectionLayout& layout = *plan.reflections;
        // One probe at the bake's cube size and a ray or two per texel, its tracing scaled to the
        // bake's rays; probes bake in parallel.
        std::unique_ptr<IrradianceCache> own;
        if (!cache) own = std::make_unique<IrradianceCache>(setup.lighting, 16, 16, 1, 0, BakeControl{});
        const ReflectionLighting light{&setup.lighting, cache ? cache.get() : own.get(), std::max(q.bounces, 1),
                                       groundRadiance(setup.lighting, rs.groundColor)};
        const int calibrationRays = std::min(rs.rayCount, 2);
        auto t = Clock::now();
        const RadianceCube cube = traceRadianceCube(light, layout.positions[layout.count() / 2], rs.resolution,
                                                    calibrationRays, 1);
        const double trace = secondsSince(t) * double(rs.rayCount) / double(calibrationRays);
        t = Clock::now();
        prefilterCube(cube);
        const double prefilter = secondsSince(t);
        ReflectionProbeSet shape;
        shape.encoding = rs.encoding;
        shape.faceSize = rs.resolution;
        shape.mipCount = cubeMipCount(rs.resolution);
        BakeEstimate::Reflection r;
        r.probes = layout.count();
        r.bytes = kRprobeHeaderBytes + r.probes * (kRprobeProbeBytes + 12 * shape.texelsPerProbe());
        const double waves = std::ceil(double(r.probes) / double(std::min<size_t>(size_t(threads), r.probes)));
        r.seconds = waves * (trace + prefilter);
        e.seconds += r.seconds;
        e.secondsMax += r.seconds;
        e.reflection = r;
    }
    for (size_t vi = 0; vi < setup.volumes.size(); ++vi) {
        const ProbeVolumeSettings& v = *setup.volumes[vi];
        const ProbeLayout& L = plan.layouts[vi];
        VolumeEstimate ve;
        ve.name = v.name;
        ve.placement = v.placement;
        ve.grid = L.cellDims;
        ve.cellSize = L.cellSize;
        ve.probes = ve.probesMax = L.validCount();
        ve.bytes = ve.bytesMax = L.fileBytes();
        ve.raysPerProbe = v.rayCount ? *v.rayCount : int(std::lround(meanRays));
        ve.borrowed = L.borrowedCells;
        const double perProbe = double(ve.raysPerProbe) * secondsPerProbeRay;
        // Error-map points trace the least rays only (measureVolumeErrorMap). A terrain grid
        // without a target, in full, bakes its map here as the bake will (plannedErrorMap): its
        // time per point, fixed costs included, stands for the map's and the suggestion trials'.
        double perMapPoint = double(raysOf(setup, v).rays) * secondsPerProbeRay;
        const bool suggests = v.placement == ProbePlacement::Terrain && !v.targetError && plan.mapPoints[vi] > 0 &&
                              !setup.referenceMode;
        std::optional<PlannedMap> planned;
        if (full && suggests) {
            planned = plannedErrorMap(setup, cache.get(), scene.bake, v, L, volumeSeed(vi));
            perMapPoint = planned->secondsPerPoint;
        }
        double probes = double(ve.probes), probesMax = probes;
        if (L.octree) {
            const AdaptiveOctree& t = *L.octree;
            ve.minCell = t.minCell;
            ve.maxCell = t.maxCell;
            ve.moved = t.moved;
            ve.borrowed = t.borrowed;
            ve.uniformProbes = t.uniformProbes;
            probes += kInterpolationPoints;
            if (v.adaptive.tolerance) {
                ve.refines = true;
                ve.tolerance = *v.adaptive.tolerance;
                // Every leaf larger than the minimum bakes its children's probes (8 octants, 4
                // quadrants) at least once.
                const double children = t.surface ? 4.0 : 8.0;
                size_t coarse = 0;
                for (const OctreeLeaf& l : t.leaves) coarse += l.level > 0;
                probes += children * double(coarse);
                // At most: every cell split down to the minimum, or the budget.
                size_t cap = t.uniformProbes + t.moved;
                ve.cap = "a uniform grid at the minimum cell size";
                if (v.adaptive.maxProbes && size_t(*v.adaptive.maxProbes) < cap) {
                    cap = size_t(*v.adaptive.maxProbes);
                    ve.cap = "adaptive.max_probes";
                }
                if (v.adaptive.maxBytes) {
                    const uint64_t fixed = 48 + 4 * uint64_t(L.cellProbe.size());
                    const uint64_t byBytes =
                        uint64_t(*v.adaptive.maxBytes) > fixed ? (uint64_t(*v.adaptive.maxBytes) - fixed) / 160 : 0;
                    if (byBytes < cap) {
                        cap = size_t(byBytes);
                        ve.cap = "adaptive.max_bytes";
                    }
                }
                ve.probesMax = std::max(ve.probes, cap);
                ve.bytesMax = 48 + 160 * uint64_t(ve.probesMax) + 4 * uint64_t(L.cellProbe.size());
                // Each split bakes its children for children - 1 more probes.
                probesMax = probes + double(ve.probesMax - ve.probes) * (1.0 + children / (children - 1.0));
            } else {
                probesMax = probes;
            }
        }
        ve.errorMapPoints = plan.mapPoints[vi];
        const double mapSeconds = double(ve.errorMapPoints) * perMapPoint;
        ve.seconds = probes * perProbe + mapSeconds;
        // measureVolumeErrorMap's suggestion: its trial grids (at most kSuggestTrials, each within
        // the terrain-grid limit) trace the least rays and reuse the map's truths. When the map
        // will be high, the first trial is the grid grownGrid makes of its mean; one that stops
        // short of the limit is taken to be followed by one at it (the exponent the two measure
        // is far below 2 on real terrain, which sends the next grid past the limit).
        if (planned) {
            const ErrorMapStats& m = planned->stats;
            ve.plannedMap = m;
            const int ax = L.probeDims[0], az = L.probeDims[2];
            bool capped = false;
            const auto [nx, nz] = grownGrid(ax, az, std::sqrt(double(ax) * az), m.mean, 2.0, capped);
            // At the limit already: no denser grid to measure (denserGrid stops).
            ve.suggestionLikely = errorIsHigh(m) && nx * nz > double(ax) * az + 0.5;
            if (ve.suggestionLikely) {
                ve.suggestionSecondsMax = double(kSuggestTrials) * double(kMaxTerrainGridProbes) * perMapPoint;
                const double trials = nx * nz + (capped ? 0.0 : double(kMaxTerrainGridProbes));
                ve.seconds += std::min(trials * perMapPoint, ve.suggestionSecondsMax);
            }
        }
        ve.secondsMax = std::max(probesMax, probes) * perProbe + mapSeconds + ve.suggestionSecondsMax;
        e.seconds += ve.seconds;
        e.secondsMax += ve.secondsMax;
        for (BakeEstimate::Scenario& sc : e.scenarios)
            sc.seconds += probes * (v.rayCount ? perProbe : sc.meanRays * secondsPerProbeRay);
        e.volumes.push_back(std::move(ve));
    }
    for (BakeEstimate::Scenario& sc : e.scenarios) {
        sc.seconds += e.cacheSeconds;
        e.seconds += sc.seconds;
        e.secondsMax += sc.seconds;
    }
    return e;
}

}  // namespace

}  // namespace terralux
