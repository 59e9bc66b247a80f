#pragma once
// One bake, start to finish: terrain, sky, placement, integration, optional reference
// comparison, then the export (.shprobe per volume, glTF scene, bake_report.json). Nothing is
// written until everything is computed, and files are staged and renamed, so a cancelled or
// failed bake leaves earlier outputs untouched.

#include <array>
#include <atomic>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "Project.h"
#include "Tiling.h"
#include "bake/ProbeDiagnostics.h"
#include "bake/ReflectionBake.h"
#include "bake/TargetSearch.h"

namespace terralux {

struct BakeRequest {
    Project project;
    int threads = 0;                          // 0 = all cores
    bool compareReference = false;            // also run the reference and report the error
    // One tile of a region (docs/farm.md): the tile's share of the terrain is placed, baked and
    // exported; the terrain within its halo is traced. The project's export.out_dir is the tile's
    // own folder.
    std::optional<TileSpec> tile;
};

struct BakeOutcome {
    nlohmann::json report;
    std::filesystem::path outDir;
    std::vector<std::filesystem::path> files;
    std::vector<std::string> warnings;  // one line each, also in the report's "warnings"
};

// What a bake depends on: every parameter the parameter table says it reads (ParameterSpec::bake)
// and the identity (path, size, modification time) of the files it reads (DEM, albedo map, HDR).
// bake_report.json records it as "inputs"; a bake whose inputs differ from the project's is stale.
nlohmann::json bakeInputs(const Project& project);
// Where two bakeInputs differ, one line each: "probe_volumes[0].grid_dims: baked [8,8], now
// [32,32]". Empty when they are the same.
std::vector<std::string> bakeInputDifferences(const nlohmann::json& baked, const nlohmann::json& now);

// Above this mean, or this 95th percentile, of the interpolation error a bake's report suggests
// denser probes ("suggestions").
inline constexpr double kSuggestAboveMeanError = 0.05;
inline constexpr double kSuggestAboveP95Error = 0.10;
// The bake's test for a high map: it then says so and, for a terrain grid, suggests a denser one.
bool errorIsHigh(const ErrorMapStats& m);

// What a volume's target_error chose (docs/lighting.md, "Asking for an accuracy"): the search's
// trials bake with a small irradiance cache and a coarse error map; the bake then measures its
// own map of the chosen layout.
struct TargetChoice {
    double target = 0.0;
    std::string setting;        // "grid_dims" or "adaptive.tolerance"
    std::string value;          // what it was set to: "48,32", "0.0150"
    std::string replaced;       // the project's own value it replaced ("8,8"); empty when unset
    size_t probes = 0;
    uint64_t bytes = 0;
    float spacing = 0.0f;       // terrain: probe spacing; adaptive: min cell, metres
    std::optional<double> tolerance;  // adaptive: the chosen adaptive.tolerance
    double p95 = 0.0;           // of the search's map
    int mapResolution = 0;      // of the search's map
    std::optional<double> bakeP95;    // of the bake's own map, once measured: the target's judge
    bool met = false;           // of the search's map
    bool capped = false;        // terrain: the target needs more than kMaxTerrainGridProbes
    size_t trials = 0;
    double seconds = 0.0;       // the search
    // Terrain grids past the cap: the adaptive volume that meets the target instead, with its
    // cost ({"set": [...], "probes", "bytes", "estimated_time_s", "p95"}); null when none does.
    nlohmann::json offer;
    std::string warning;        // one line when capped
};
// "spacing 240 m, 3 914 probes, p95 2.8 %", the p95 of the bake's map once measured.
std::string targetSummary(const TargetChoice& c);
// met and p95 judged on the bake's map once measured, on the search's until then.
nlohmann::json targetChoiceReport(const TargetChoice& c);

// The light a bake's reflection rays read: terrain hits from `sharedCache` (the probes' own) when
// given, else from a cache built into `own` with the bake's bounces less the one the reflection ray
// makes (at `cacheResolution`, or the standard preset's when 0); the ground beyond the terrain
// has albedo `groundColor`.
ReflectionLighting reflectionLightingOf(const BakeLighting& lighting, const BakeQuality& q, const glm::vec3& groundColor,
                                        const IrradianceCache* sharedCache, int cacheResolution,
                                        std::unique_ptr<IrradianceCache>& own, const BakeControl& control);

// What bake.target_error chose (docs/lighting.md, "Asking for an accuracy"): bounces until one
// more changes the irradiance of a few of the volumes' own probes by less than the target, then
// the fewest rays whose Monte Carlo standard error meets it there. The bake then judges the
// target on all of its probes' standard error.
struct SamplingChoice {
    double target = 0.0;
    int rays = 0, bounces = 0;
    std::string replaced;            // what it overrides: "the standard preset's 256 rays and 2 bounces"
    size_t pilotProbes = 0;          // probes the trials bake
    SamplingSearch raySearch, bounceSearch;
    bool met = false;                // both searches met it on the pilot probes
    double seconds = 0.0;
    std::string summary;             // "1 024 rays (p95 standard error 1.8 %), 3 bounces (a 4th adds 0.6 %)"
};
nlohmann::json samplingChoiceReport(const SamplingChoice& c);

// Phase name and progress in [0, 1] of the whole bake.
using BakeProgress = std::function<void(const std::string& phase, double fraction)>;

// Throws DemError / ImageError / ProjectError / PlacementError for bad input, BakeCancelled
// when `cancel` was set, FileWriteError when the export fails.
BakeOutcome runBake(const BakeRequest& request, const BakeProgress& progress,
                    const std::atomic<bool>* cancel);

// What a bake would place and cost, without baking or writing anything (`terralux --bake
// --dry-run`, the bake dialog). Times come from a calibration bake of a few of the volume's own
// probes and a small irradiance cache on this terrain, scaled by ray and point counts.
struct VolumeEstimate {
    std::string name;
    ProbePlacement placement = ProbePlacement::Terrain;
    std::array<uint32_t, 3> grid{1, 1, 1};  // .shprobe cells
    float cellSize = 0.0f;
    size_t probes = 0;                      // placed (adaptive: the geometric octree)
    uint64_t bytes = 0;                     // its .shprobe size
    int raysPerProbe = 0;                   // fixed, or the mean a target's rounds reached on sampled probes
    size_t errorMapPoints = 0;              // probes baked for the interpolation-error map (at most)
    double seconds = 0.0;
    // A terrain grid without a target whose map comes out high measures denser grids: at most
    // kSuggestTrials grids of the terrain-grid limit at the least rays (in secondsMax). Set by the
    // dry run when its map of the grid says the bake will.
    double suggestionSecondsMax = 0.0;
    // Its map, baked by the dry run as the bake will, is high: the expected trials count in `seconds`.
    bool suggestionLikely = false;
    std::optional<ErrorMapStats> plannedMap;  // that map (dry run, terrain grids without a target)
    // Adaptive volumes.
    double minCell = 0.0, maxCell = 0.0;
    size_t moved = 0, borrowed = 0;
    size_t uniformProbes = 0;               // a uniform grid at the minimum cell size
    // Error-driven volumes: the refinement adds probes, at most up to `cap`.
    bool refines = false;
    double tolerance = 0.0;
    size_t probesMax = 0;
    uint64_t bytesMax = 0;
    double secondsMax = 0.0;
    std::string cap;
    std::optional<TargetChoice> target;     // target_error chose the placement
};

struct BakeEstimate {
    std::vector<VolumeEstimate> volumes;
    int threads = 0;
    std::string quality;
    int rays = 0, bounces = 0;
    std::string raysText;             // "256 rays" or the preset's target and range (raysDescription)
    double meanRays = 0.0;            // per probe, as the sampled probes traced
    double cacheSeconds = 0.0;
    double loadSeconds = 0.0;         // the terrain, sky and albedo, as this estimate loaded them
    double writeSeconds = 0.0;        // the glTF scene's mesh, timed on a small one and scaled
    double probeRaysPerSecond = 0.0;  // measured on this terrain, with this lighting
    double seconds = 0.0;             // everything, with error-driven volumes at their minimum
    double secondsMax = 0.0;          // with error-driven volumes at their cap
    // Reflection probes, when enabled: a probe traced and prefiltered here, scaled by the rays.
    struct Reflection {
        size_t probes = 0;
        uint64_t bytes = 0;           // probes.rprobe
        double seconds = 0.0;
    };
    std::optional<Reflection> reflection;
    // Lighting scenarios: each bakes a cache and the probes of the same layouts again (no error
    // map). A scenario's light changes how many rays its probes need (a low sun is noisier):
    // the sampled probes are baked again under its light for its own mean.
    struct Scenario {
        std::string name;
        double meanRays = 0.0;  // per probe, as the sampled probes traced under its light
        double seconds = 0.0;
    };
    std::vector<Scenario> scenarios;
    bool lpvIni = false;   // lpv.enabled: the bake writes lpv.ini and TERRALUX_lighting.lpv
    size_t lights = 0;     // local lights: KHR_lights_punctual
    std::optional<SamplingChoice> sampling;  // bake.target_error chose rays and bounces
    std::vector<std::string> warnings;  // one line each (a target past the terrain-grid limit)
};

// Throws the same input errors as runBake.
BakeEstimate estimateBake(const BakeRequest& request);

// The project as its bake bakes it: what bake.target_error and each volume's target_error choose
// written into bake.rays, bake.bounces, grid_dims or adaptive.tolerance, and the targets cleared.
// A project without targets comes back as it is, without loading anything.
Project resolveTargets(const Project& project, int threads = 0);

}  // namespace terralux
