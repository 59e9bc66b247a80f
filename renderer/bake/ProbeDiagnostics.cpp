#include "bake/ProbeDiagnostics.h"

#include <algorithm>
#include <cmath>

#include "bake/SphereSampling.h"

namespace terralux {

ErrorMapStats errorMapStats(const ErrorMap& map) {
    ErrorMapStats s;
    std::vector<float> e;
    for (float x : map.error)
        if (std::isfinite(x)) e.push_back(x);
    s.points = e.size();
    s.uncovered = map.error.size() - e.size();
    static_cast<Spread&>(s) = spreadOf(std::move(e));
    return s;
}

ProbeDiagnostics describeProbes(const ProbeLayout& L, std::span<const float> standardError) {
    ProbeDiagnostics d;
    for (size_t i = 0; i < L.positions.size(); ++i) {
        if (!L.valid[i]) {
            // Adaptive leaves without a probe of their own are not rejected probes: their cells
            // borrow the probe above or hold -1 (the report counts them).
            if (!L.octree) d.rejected.push_back(L.positions[i]);
            continue;
        }
        d.positions.push_back(L.positions[i]);
        if (!standardError.empty()) d.standardError.push_back(standardError[i]);
        d.moved.push_back(L.octree && L.octree->probe[i] == LeafProbe::Moved ? 1 : 0);
    }
    if (L.octree)
        for (size_t i = 0; i < L.octree->leaves.size(); ++i) {
            const OctreeLeaf& leaf = L.octree->leaves[i];
            const float edge = L.cellSize * float(leaf.edge());
            // A surface square has no height of its own: its cube is centred on its probe.
            const float y = L.octree->surface ? L.positions[i].y - 0.5f * edge
                                              : L.cellOrigin.y + L.cellSize * float(leaf.y);
            d.leaves.emplace_back(L.cellOrigin.x + L.cellSize * float(leaf.x), y,
                                  L.cellOrigin.z + L.cellSize * float(leaf.z), edge);
        }
    return d;
}

float errorMapHeight(const ProbeVolumeSettings& v, const ProbeLayout& L) {
    if (followsSurface(v.placement) && v.heightOffset > 0.0) return float(v.heightOffset);
    return 0.02f * L.cellSize;
}

ErrorMap errorMapGrid(const ProbeLayout& L, const Heightfield& hf, int resolution, float height) {
    ErrorMap m;
    if (resolution <= 0) return m;
    const double x0 = std::max<double>(L.cellOrigin.x, hf.minX());
    const double z0 = std::max<double>(L.cellOrigin.z, hf.minZ());
    const double x1 = std::min<double>(L.cellOrigin.x + double(L.cellSize) * L.cellDims[0], hf.maxX());
    const double z1 = std::min<double>(L.cellOrigin.z + double(L.cellSize) * L.cellDims[2], hf.maxZ());
    if (!(x1 > x0) || !(z1 > z0)) return m;
    const double step = std::max(x1 - x0, z1 - z0) / double(resolution);
    m.nx = uint32_t(std::clamp(std::lround((x1 - x0) / step), 1l, long(resolution)));
    m.nz = uint32_t(std::clamp(std::lround((z1 - z0) / step), 1l, long(resolution)));
    // Points at the centres of the map's cells, so the map spans the footprint symmetrically.
    m.step = float(step);
    m.x0 = float(x0 + 0.5 * ((x1 - x0) - step * double(m.nx - 1)));
    m.z0 = float(z0 + 0.5 * ((z1 - z0) - step * double(m.nz - 1)));
    m.height = height;
    m.error.assign(size_t(m.nx) * m.nz, NAN);
    return m;
}

ErrorMap measureErrorMap(const ProbeLayout& L, const std::vector<sh::ShRgb>& sh,
                         const Heightfield& hf, const ProbeBaker& baker, int resolution,
                         float height, uint64_t seed, std::unordered_map<size_t, sh::ShRgb>* truths) {
    ErrorMap m = errorMapGrid(L, hf, resolution, height);
    std::vector<glm::vec3> points, missing;
    std::vector<uint64_t> keys;
    std::vector<size_t> slot, missingSlot;
    for (uint32_t j = 0; j < m.nz; ++j)
        for (uint32_t i = 0; i < m.nx; ++i) {
            const float x = m.x0 + m.step * float(i), z = m.z0 + m.step * float(j);
            const glm::vec3 p(x, hf.surfaceHeight(x, z) + m.height, z);
            sh::ShRgb unused;
            if (!interpolateProbes(L, sh, p, unused)) continue;
            const size_t k = size_t(j) * m.nx + i;
            points.push_back(p);
            slot.push_back(k);
            if (truths && truths->count(k)) continue;
            missing.push_back(p);
            missingSlot.push_back(k);
            keys.push_back(splitmix64(seed ^ 0xE7707A9ull ^ (uint64_t(k) * 0x9E3779B97F4A7C15ull)));
        }
    if (points.empty()) return m;
    std::unordered_map<size_t, sh::ShRgb> own;
    std::unordered_map<size_t, sh::ShRgb>& known = truths ? *truths : own;
    if (!missing.empty()) {
        const ProbeBake baked = baker(missing, keys);
        for (size_t n = 0; n < missing.size(); ++n) known[missingSlot[n]] = baked.sh[n];
    }
    std::vector<sh::ShRgb> truth;
    truth.reserve(points.size());
    for (size_t k : slot) truth.push_back(known.at(k));
    const double floor = interpolationErrorFloor(truth);
    for (size_t n = 0; n < points.size(); ++n) {
        sh::ShRgb value;
        interpolateProbes(L, sh, points[n], value);
        m.error[slot[n]] = relativeIrradianceError(value, truth[n], floor);
    }
    return m;
}

}  // namespace terralux
