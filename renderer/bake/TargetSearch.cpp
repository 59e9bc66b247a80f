#include "bake/TargetSearch.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "bake/SphereSampling.h"

namespace terralux {

std::array<int, 3> terrainDimsFor(const Heightfield& hf, int perSide) {
    const double spanX = hf.maxX() - hf.minX(), spanZ = hf.maxZ() - hf.minZ();
    const int n = std::max(perSide, 2);
    const double spacing = std::max(spanX, spanZ) / double(n - 1);
    auto along = [&](double span) {
        return span >= std::max(spanX, spanZ) ? n : std::clamp(int(std::lround(span / spacing)) + 1, 2, n);
    };
    return {along(spanX), 1, along(spanZ)};
}

int maxPerSide(const Heightfield& hf, int maxProbes) {
    int n = 2;
    while (true) {
        const auto d = terrainDimsFor(hf, n + 1);
        if (int64_t(d[0]) * d[2] > maxProbes) return n;
        ++n;
    }
}

namespace {

// Smallest index in [lo, hi] whose error meets `target`, error taken as falling with the index.
// `guess(i, e)` is the model's index for the target from a trial at i with error e. Returns hi + 1
// when even hi misses.
int bisect(int lo, int hi, int start, double target, const std::function<double(int)>& error,
           const std::function<int(int, double)>& guess) {
    int fail = lo - 1, pass = hi + 1;
    std::map<int, double> seen;
    int next = std::clamp(start, lo, hi);
    bool modelStep = true;
    while (pass - fail > 1) {
        if (seen.count(next) || next <= fail || next >= pass) next = fail + (pass - fail) / 2;
        const double e = error(next);
        seen[next] = e;
        if (e <= target) pass = next;
        else fail = next;
        if (pass - fail <= 1) break;
        // Model and bisection alternate: the model is fast where it holds, bisection bounds the
        // steps where it does not.
        next = modelStep ? std::clamp(guess(next, e), fail + 1, pass - 1) : fail + (pass - fail) / 2;
        modelStep = !modelStep;
    }
    return pass;
}

}  // namespace

SamplingSearch searchRays(double target, int minRays, int maxRays, int startRays,
                          const std::function<double(int)>& p95At) {
    const auto log2Of = [](int n) { return int(std::ceil(std::log2(double(std::max(n, 1))) - 1e-9)); };
    const int lo = log2Of(minRays), hi = std::max(lo, int(std::floor(std::log2(double(std::max(maxRays, 1))))));
    SamplingSearch s;
    std::map<int, double> seen;
    auto error = [&](int k) {
        const double e = p95At(1 << k);
        seen[k] = e;
        s.trials.push_back({1 << k, e});
        return e;
    };
    // error ∝ N^(-3/4): N·(e/target)^(4/3) rays meet it, log2 of that is k + (4/3)·log2(e/target).
    const auto guess = [&](int k, double e) {
        if (!(e > 0.0)) return lo;
        return int(std::ceil(double(k) + (4.0 / 3.0) * std::log2(e / target) - 1e-9));
    };
    const int pass = bisect(lo, hi, log2Of(startRays), target, error, guess);
    const int k = std::min(pass, hi);
    if (!seen.count(k)) error(k);
    s.chosen = 1 << k;
    s.error = seen[k];
    s.met = pass <= hi;
    return s;
}

SamplingSearch searchBounces(double target, int maxBounces, const std::function<double(int)>& changeAfter) {
    SamplingSearch s;
    for (int b = 0; b < maxBounces; ++b) {
        const double change = changeAfter(b);
        s.trials.push_back({b, change});
        if (change < target) {
            s.chosen = b;
            s.error = change;
            s.met = true;
            return s;
        }
    }
    s.chosen = std::max(maxBounces, 0);
    s.error = s.trials.empty() ? 0.0 : s.trials.back().error;
    return s;
}

PlacementSearch searchTerrainGrid(const Heightfield& hf, double target, int maxProbes, int startPerSide,
                                  const GridTrialFn& trial) {
    PlacementSearch s;
    const int top = maxPerSide(hf, maxProbes);
    std::map<int, size_t> at;  // per side -> trial
    auto error = [&](int n) {
        s.trials.push_back(trial(terrainDimsFor(hf, n)));
        at[n] = s.trials.size() - 1;
        return s.trials.back().p95;
    };
    // Error ∝ spacing² ∝ 1/(n - 1)²: the count that brings e down to the target.
    auto guess = [&](int n, double e) {
        if (!(e > 0.0)) return 2;
        return int(std::ceil(1.0 + double(n - 1) * std::sqrt(e / target)));
    };
    const int pass = bisect(2, top, startPerSide, target, error, guess);
    s.met = pass <= top;
    s.capped = !s.met;
    const int chosen = s.met ? pass : top;
    if (!at.count(chosen)) error(chosen);
    s.chosen = s.trials[at[chosen]];
    return s;
}

void confirmTerrainGrid(const Heightfield& hf, double target, int maxProbes, PlacementSearch& s,
                        const GridTrialFn& fine) {
    const int top = maxPerSide(hf, maxProbes);
    int n = std::max(s.chosen.dims[0], s.chosen.dims[2]);
    PlacementTrial t = fine(terrainDimsFor(hf, n));
    s.trials.push_back(t);
    while (t.p95 > target && n < top) {
        t = fine(terrainDimsFor(hf, ++n));
        s.trials.push_back(t);
    }
    s.chosen = t;
    s.met = t.p95 <= target;
    s.capped = !s.met;
}

PlacementSearch searchAdaptiveTolerance(double target, const ToleranceTrialFn& trial) {
    PlacementSearch s;
    constexpr int kFinest = -12, kCoarsest = 4;
    // Index i = -k: the smallest i that meets is the largest tolerance.
    auto tolerance = [&](int i) { return target * std::exp2(-double(i) / 2.0); };
    std::map<int, size_t> at;
    auto error = [&](int i) {
        s.trials.push_back(trial(tolerance(i)));
        at[i] = s.trials.size() - 1;
        return s.trials.back().p95;
    };
    // A leaf's split test bounds its error by the tolerance: halve the tolerance by the miss.
    auto guess = [&](int i, double e) {
        if (!(e > 0.0)) return -kCoarsest;
        return i + int(std::ceil(2.0 * std::log2(e / target)));
    };
    const int pass = bisect(-kCoarsest, -kFinest, 0, target, error, guess);
    s.met = pass <= -kFinest;
    s.capped = !s.met;
    if (s.met) {
        s.chosen = s.trials[at[pass]];
    } else {
        // Nothing met: the trial that came closest.
        s.chosen = *std::min_element(s.trials.begin(), s.trials.end(),
                                     [](const auto& a, const auto& b) { return a.p95 < b.p95; });
    }
    s.capped = s.capped || s.chosen.budgetReached;
    return s;
}

namespace {

PlacementTrial fromLayout(const ProbeLayout& L, const std::vector<sh::ShRgb>& sh, const ProbeVolumeSettings& v,
                          const Heightfield& hf, const ProbeBaker& baker, int resolution, uint64_t seed) {
    PlacementTrial t;
    t.probes = L.validCount();
    t.bytes = L.fileBytes();
    const ErrorMap map = measureErrorMap(L, sh, hf, baker, resolution, errorMapHeight(v, L), seed);
    const ErrorMapStats st = errorMapStats(map);
    t.p95 = st.p95;
    t.points = st.points;
    return t;
}

}  // namespace

PlacementTrial measureGridTrial(ProbeVolumeSettings v, const Heightfield& hf, const std::array<int, 3>& dims,
                                const ProbeBaker& baker, int resolution, uint64_t seed) {
    v.gridDims = dims;
    v.spacing.reset();
    const ProbeLayout L = placeProbes(v, hf);
    std::vector<glm::vec3> positions;
    std::vector<uint64_t> keys;
    std::vector<size_t> index;
    for (size_t i = 0; i < L.positions.size(); ++i)
        if (L.valid[i]) {
            positions.push_back(L.positions[i]);
            keys.push_back(splitmix64(seed ^ (uint64_t(i) * 0x9E3779B97F4A7C15ull)));
            index.push_back(i);
        }
    std::vector<sh::ShRgb> sh(L.positions.size());
    if (!positions.empty()) {
        const ProbeBake b = baker(positions, keys);
        for (size_t k = 0; k < index.size(); ++k) sh[index[k]] = b.sh[k];
    }
    PlacementTrial t = fromLayout(L, sh, v, hf, baker, resolution, seed);
    t.dims = dims;
    t.spacing = std::max(L.spacing.x, L.spacing.z);
    return t;
}

PlacementTrial measureAdaptiveTrial(ProbeVolumeSettings v, const Heightfield& hf, double tolerance,
                                    const ProbeBaker& baker, int resolution, uint64_t seed) {
    v.adaptive.tolerance = tolerance;
    const AdaptiveBake a = bakeAdaptive(v, hf, baker);
    PlacementTrial t = fromLayout(a.layout, a.bake.sh, v, hf, baker, resolution, seed);
    t.tolerance = tolerance;
    t.spacing = a.layout.cellSize;
    t.budgetReached = a.refinement && a.refinement->budgetReached;
    return t;
}

}  // namespace terralux
