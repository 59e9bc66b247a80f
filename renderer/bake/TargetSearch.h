#pragma once
// Placement from an accuracy (docs/lighting.md, "Asking for an accuracy"): the coarsest terrain
// grid, or the largest adaptive tolerance, whose measured interpolation error meets a target at
// the 95th percentile of the error map. Each trial bakes a layout and measures its map; the
// search is a bisection on the probes per side (or the tolerance step) that takes its first
// steps from the model "error grows with spacing²".

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "bake/AdaptivePlacement.h"
#include "bake/ProbeDiagnostics.h"
#include "scene/SceneDescription.h"
#include "terrain/Heightfield.h"

namespace terralux {

// One measured layout.
struct PlacementTrial {
    std::array<int, 3> dims{1, 1, 1};  // terrain: grid_dims (nx, 1, nz)
    double tolerance = 0.0;            // adaptive: adaptive.tolerance
    size_t probes = 0;                 // valid probes
    uint64_t bytes = 0;                // .shprobe size
    float spacing = 0.0f;              // terrain: the larger probe spacing; adaptive: min cell, metres
    double p95 = 0.0;                  // error map, 95th percentile over covered points
    size_t points = 0;                 // covered map points
    bool budgetReached = false;        // adaptive: max_probes / max_bytes stopped the refinement
};

struct PlacementSearch {
    PlacementTrial chosen;
    bool met = false;     // chosen.p95 <= target
    // Terrain: the target needs more probes than the limit allows; chosen is the densest grid
    // within it. Adaptive: even the finest tolerance tried misses (or the budget stopped it).
    bool capped = false;
    std::vector<PlacementTrial> trials;  // in the order measured
};

// Terrain-grid dims with `perSide` probes along the footprint's longer side and the shorter side
// spaced as near the same as whole probes allow (at least 2 each).
std::array<int, 3> terrainDimsFor(const Heightfield& hf, int perSide);
// The most probes per side whose terrain grid holds at most `maxProbes`.
int maxPerSide(const Heightfield& hf, int maxProbes);

using GridTrialFn = std::function<PlacementTrial(const std::array<int, 3>& dims)>;
// The coarsest terrain grid (fewest per side) whose trial meets `target`, starting at
// `startPerSide`, never above `maxProbes`. Error is taken as monotone in the spacing: each step is
// the spacing² model's guess from the last trial, kept strictly inside the bracket of failing and
// passing counts, or its midpoint when the guess is already measured.
PlacementSearch searchTerrainGrid(const Heightfield& hf, double target, int maxProbes, int startPerSide,
                                  const GridTrialFn& trial);

// Confirms a search's choice on a finer map (`fine`: the bake's own resolution): while the chosen
// grid misses there, one more probe a side, up to `maxProbes`. The confirmed trial replaces the
// choice and joins the trials.
void confirmTerrainGrid(const Heightfield& hf, double target, int maxProbes, PlacementSearch& search,
                        const GridTrialFn& fine);

using ToleranceTrialFn = std::function<PlacementTrial(double tolerance)>;
// The largest adaptive tolerance on the ladder target·2^(k/2), k in [-12, 4], whose trial meets
// `target`, bisecting on k from k = 0.
PlacementSearch searchAdaptiveTolerance(double target, const ToleranceTrialFn& trial);

// Rays and bounces from an accuracy (bake.target_error; docs/lighting.md, "Asking for an accuracy").
struct SamplingTrial {
    int value = 0;       // rays per probe, or bounces
    double error = 0.0;  // rays: p95 of the probes' relative standard error; bounces: p95 of the
                         // relative change of irradiance that one more bounce makes
};
struct SamplingSearch {
    int chosen = 0;
    double error = 0.0;  // of the chosen value
    bool met = false;
    std::vector<SamplingTrial> trials;  // in the order measured
};
// The fewest rays per probe, a power of two in [minRays, maxRays], whose measured p95 standard
// error meets `target`, from `startRays`. Steps follow the quasi-Monte Carlo model error ∝ N^(-3/4)
// of a spherical Fibonacci lattice (docs/lighting.md, "Monte Carlo standard error"), alternating
// with plain bisection of the bracket. When even maxRays misses, maxRays, not met.
SamplingSearch searchRays(double target, int minRays, int maxRays, int startRays,
                          const std::function<double(int rays)>& p95At);
// The fewest bounces b in [0, maxBounces) after which one more changes irradiance by less than
// `target` (`changeAfter(b)` measures b against b + 1), tried in order since the change falls
// with each bounce. When none does, maxBounces, not met, with the last change measured.
SamplingSearch searchBounces(double target, int maxBounces, const std::function<double(int bounces)>& changeAfter);

// The trial of a terrain grid: `volume` placed with `dims`, its probes baked with `baker`, its
// error map measured at `resolution` (the truth baked by the same baker).
PlacementTrial measureGridTrial(ProbeVolumeSettings volume, const Heightfield& hf, const std::array<int, 3>& dims,
                                const ProbeBaker& baker, int resolution, uint64_t seed);
// The trial of an adaptive volume refined at `tolerance`.
PlacementTrial measureAdaptiveTrial(ProbeVolumeSettings volume, const Heightfield& hf, double tolerance,
                                    const ProbeBaker& baker, int resolution, uint64_t seed);

}  // namespace terralux
