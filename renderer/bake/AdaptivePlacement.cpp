#include "bake/AdaptivePlacement.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include <glm/common.hpp>
#include <glm/vec3.hpp>
#include <tbb/parallel_for.h>

#include "bake/SphereSampling.h"

namespace terralux {
namespace {

std::string num(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}
std::string whole(double v) {
    std::ostringstream s;
    s << std::fixed << std::setprecision(0) << v;
    return s.str();
}

// Deepest octree: max_cell_size up to min_cell_size x 2^16 (the project validates the same).
constexpr int kMaxLevels = 16;
// Where a moved probe goes, and the least height of any probe above the surface: a share of the
// cell edge.
constexpr double kMoveClearance = 0.02;

struct Range {
    float lo = INFINITY, hi = -INFINITY;
    void add(const Range& r) {
        lo = std::min(lo, r.lo);
        hi = std::max(hi, r.hi);
    }
};

uint64_t flatIndex(const OctreeLeaf& l, const std::array<uint32_t, 3>& dims) {
    return uint64_t(l.x) + uint64_t(l.y) * dims[0] + uint64_t(l.z) * dims[0] * dims[1];
}

}  // namespace

double autoMinCellSize(const Heightfield& hf, const glm::dvec3& box) {
    return std::max({double(hf.cellSizeX()), double(hf.cellSizeZ()),
                     std::max(box.x, box.z) / kAutoMinCellsAlongBox});
}

double autoSurfaceMinCell(const Heightfield& hf, double heightOffset) {
    const double sx = double(hf.maxX()) - hf.minX(), sz = double(hf.maxZ()) - hf.minZ();
    const double tall = double(hf.maxHeight()) - hf.minHeight() + std::max(heightOffset, 0.0);
    auto cells = [&](double m) {
        return std::max(1.0, std::ceil(sx / m)) * std::max(1.0, std::ceil(sz / m)) * (std::ceil(tall / m) + 1.0);
    };
    double m = 0.5 * std::max(hf.cellSizeX(), hf.cellSizeZ());
    while (cells(m) > kAutoSurfaceCells) m *= 1.02;
    return m;
}

double autoSurfaceMaxCell(const Heightfield& hf, double minCell) {
    const double side = std::max(double(hf.maxX()) - hf.minX(), double(hf.maxZ()) - hf.minZ());
    const int k = std::clamp(int(std::floor(std::log2(side / 8.0 / minCell) + 1e-9)), 0, kMaxLevels);
    return minCell * std::exp2(k);
}

namespace {

// Throws PlacementError when a layout of an error-refined volume exceeds its budgets (`what`
// names the part of the layout that does; `raise` the settings that make it smaller).
void checkRefinementBudget(const ProbeVolumeSettings& v, const ProbeLayout& L, const char* what, const std::string& raise) {
    const std::string where = "probe_volumes '" + v.name + "': " + what + " needs ";
    const AdaptiveVolumeSettings& a = v.adaptive;
    if (a.maxProbes && L.validCount() > size_t(*a.maxProbes))
        throw PlacementError(where + std::to_string(L.validCount()) + " probes, more than adaptive.max_probes = " +
                             std::to_string(*a.maxProbes) + "; raise it, " + raise);
    if (L.validCount() > size_t(kMaxVolumeProbes))
        throw PlacementError(where + std::to_string(L.validCount()) + " probes, more than an adaptive volume's limit of " +
                             std::to_string(kMaxVolumeProbes) + "; raise " + raise);
    if (a.maxBytes && L.fileBytes() > uint64_t(*a.maxBytes))
        throw PlacementError(where + std::to_string(L.fileBytes()) + " bytes, more than adaptive.max_bytes = " +
                             std::to_string(*a.maxBytes) + "; raise it, " + raise);
}

// k with max = min x 2^k, k in [0, kMaxLevels] (cells halve), or PlacementError.
int levelsBetween(const std::string& where, double min, double max, bool minSet) {
    const double ratio = max / min;
    const double k = std::round(std::log2(ratio));
    if (!(ratio >= 1.0) || k > kMaxLevels || std::abs(ratio - std::exp2(k)) > 1e-9 * ratio)
        throw PlacementError(where + ": adaptive.max_cell_size = " + num(max) + " must be min_cell_size (" + num(min) +
                             (minSet ? "" : ", the auto size") + ") times 2^k, k in [0, " +
                             std::to_string(kMaxLevels) + "]");
    return int(k);
}

// The octree of one volume: resolved settings, box and the surface ranges of its columns.
class Octree {
public:
    static constexpr size_t kChildren = 8;
    Octree(const ProbeVolumeSettings& v, const Heightfield& hf) : hf_(hf), v_(v) {
        const std::string where = "probe_volumes '" + v.name + "'";
        const AdaptiveVolumeSettings& a = v.adaptive;
        const AdaptiveBox box = adaptiveBox(v, hf);
        origin_ = box.origin;
        const glm::dvec3 size = box.size;
        m_ = a.minCellSize ? *a.minCellSize : autoMinCellSize(hf, size);
        levels_ = levelsBetween(where, m_, a.maxCellSize ? *a.maxCellSize : 16.0 * m_, a.minCellSize.has_value());
        if (a.surfaceCellSize) {
            // The largest octree cell size at or below it: a size set in metres stays valid when
            // an auto min cell moves with the box. 1e-5 forgives a size written to 6 digits.
            const double sr = *a.surfaceCellSize / m_;
            if (!(sr >= 1.0 - 1e-5))
                throw PlacementError(where + ": adaptive.surface_cell_size = " + num(*a.surfaceCellSize) +
                                     " must be at least min_cell_size (" + num(m_) +
                                     (a.minCellSize ? "" : ", the auto size") + ")");
            surfaceLevel_ = std::clamp(int(std::floor(std::log2(sr) + 1e-5)), 0, levels_);
        }
        band_ = a.surfaceBand ? *a.surfaceBand : m_;
        share_ = a.maxMoveShare;

        // Whole minimum cells; the box grows to the next one (1e-6 forgives rounding).
        double cells = 1.0;
        for (int i = 0; i < 3; ++i) {
            const double n = std::max(1.0, std::ceil(size[i] / m_ - 1e-6));
            dimsD_[i] = n;
            cells *= n;
        }
        if (cells > double(kMaxOccupancyCells))
            throw PlacementError(where + ": occupancy grid of " + whole(cells) + " cells (" +
                                 whole(dimsD_[0]) + " x " + whole(dimsD_[1]) + " x " + whole(dimsD_[2]) +
                                 " of " + num(m_) + " m) exceeds " +
                                 std::to_string(kMaxOccupancyCells) +
                                 "; raise adaptive.min_cell_size or shrink the box");
        for (int i = 0; i < 3; ++i) dims_[size_t(i)] = uint32_t(dimsD_[i]);
        buildColumnRanges();
    }

    double maxCell() const { return m_ * std::exp2(levels_); }

    // In float, as a uniform box grid computes its cell centres, so both agree on which centres
    // are above the terrain.
    glm::vec3 centre(const OctreeLeaf& n) const {
        const float h = 0.5f * float(n.edge());
        return glm::vec3(origin_) +
               float(m_) * glm::vec3(float(n.x) + h, float(n.y) + h, float(n.z) + h);
    }
    bool aboveSurface(const glm::vec3& p) const { return p.y > hf_.surfaceHeight(p.x, p.z); }
    bool centreInside(const OctreeLeaf& n) const { return !aboveSurface(centre(n)); }
    std::array<OctreeLeaf, 8> children(const OctreeLeaf& n) const {
        std::array<OctreeLeaf, 8> c;
        const uint32_t h = n.edge() / 2;
        for (uint32_t i = 0; i < 8; ++i)
            c[i] = {n.x + (i & 1) * h, n.y + ((i >> 1) & 1) * h, n.z + ((i >> 2) & 1) * h,
                    uint8_t(n.level - 1)};
        return c;
    }

    // The probe the refinement bakes for a child: at its centre.
    glm::vec3 trial(const OctreeLeaf& c) const { return centre(c); }

    // Applies the geometric rules to one cell, appending the leaves it becomes.
    void visit(const OctreeLeaf& n, std::vector<OctreeLeaf>& out, size_t& splitForInside) const {
        if (n.x >= dims_[0] || n.y >= dims_[1] || n.z >= dims_[2]) return;
        const uint32_t s = n.edge();
        if (n.x + s > dims_[0] || n.y + s > dims_[1] || n.z + s > dims_[2]) {
            // Sticks out of the box (never at the minimum size: the box is whole min cells).
            for (const OctreeLeaf& c : children(n)) visit(c, out, splitForInside);
            return;
        }
        const Range& r = range(n);
        const double y0 = origin_.y + m_ * n.y, y1 = y0 + m_ * s;
        if (y1 <= r.lo) return;  // wholly inside the terrain
        if (n.level > 0) {
            const bool inside = centreInside(n);
            if (inside || (n.level > surfaceLevel_ && y0 < double(r.hi) + band_)) {
                splitForInside += inside;
                for (const OctreeLeaf& c : children(n)) visit(c, out, splitForInside);
                return;
            }
        }
        out.push_back(n);
    }

    std::vector<OctreeLeaf> build(size_t& splitForInside) const {
        const uint32_t root = 1u << levels_;
        const uint32_t rx = (dims_[0] + root - 1) / root, ry = (dims_[1] + root - 1) / root,
                       rz = (dims_[2] + root - 1) / root;
        const size_t roots = size_t(rx) * ry * rz;
        std::vector<std::vector<OctreeLeaf>> perRoot(roots);
        std::vector<size_t> split(roots, 0);
        tbb::parallel_for(size_t(0), roots, [&](size_t i) {
            const OctreeLeaf n{uint32_t(i % rx) * root, uint32_t((i / rx) % ry) * root,
                               uint32_t(i / (size_t(rx) * ry)) * root, uint8_t(levels_)};
            visit(n, perRoot[i], split[i]);
        });
        std::vector<OctreeLeaf> leaves;
        for (size_t i = 0; i < roots; ++i) {
            leaves.insert(leaves.end(), perRoot[i].begin(), perRoot[i].end());
            splitForInside += split[i];
        }
        return leaves;
    }

    // The probe of a leaf: its centre, moved up, or none. A centre closer above the surface than
    // the clearance moves up too: a probe on the surface itself sees the terrain from below
    // through rounding (float surface, double tracer).
    LeafProbe resolve(const OctreeLeaf& n, glm::vec3& p) const {
        p = centre(n);
        const float ground = hf_.surfaceHeight(p.x, p.z);
        const double cellEdge = m_ * n.edge();
        const float target = float(double(ground) + kMoveClearance * cellEdge);
        if (p.y >= target) return LeafProbe::Centre;
        if (n.level == 0 && target > ground && double(target) - double(p.y) <= share_ * cellEdge) {
            p.y = target;
            return LeafProbe::Moved;
        }
        // Above, but too close to move within the cap: it stays (max_move_share 0 asks for that).
        if (p.y > ground) return LeafProbe::Centre;
        return LeafProbe::Dropped;
    }

    ProbeLayout layout(std::vector<OctreeLeaf> leaves, size_t splitForInside) const {
        std::sort(leaves.begin(), leaves.end(), [&](const OctreeLeaf& a, const OctreeLeaf& b) {
            return flatIndex(a, dims_) < flatIndex(b, dims_);
        });
        ProbeLayout L;
        L.probeDims = {int(dims_[0]), int(dims_[1]), int(dims_[2])};
        L.spacing = glm::vec3(float(m_));
        L.fallbackBlendDistance =
            v_.fallbackBlendDistance ? float(*v_.fallbackBlendDistance) : 2.0f * float(m_);
        L.cellSize = float(m_);
        L.cellOrigin = glm::vec3(origin_);
        L.cellDims = dims_;
        L.cellProbe.assign(size_t(dims_[0]) * dims_[1] * dims_[2], -1);
        AdaptiveOctree t;
        t.minCell = m_;
        t.maxCell = maxCell();
        t.surfaceBand = band_;
        t.surfaceCell = m_ * std::exp2(surfaceLevel_);
        t.levels = levels_;
        t.splitForInside = splitForInside;
        const size_t n = leaves.size();
        L.positions.resize(n);
        L.valid.resize(n);
        L.probeKeys.resize(n);
        t.probe.resize(n);
        tbb::parallel_for(size_t(0), n, [&](size_t i) {
            t.probe[i] = resolve(leaves[i], L.positions[i]);
            L.valid[i] = t.probe[i] != LeafProbe::Dropped;
            L.probeKeys[i] = octreeLeafKey(leaves[i]);
        });
        const size_t layer = size_t(dims_[0]) * dims_[1];
        for (size_t i = 0; i < n; ++i) {
            if (!L.valid[i]) continue;
            const OctreeLeaf& l = leaves[i];
            const uint32_t e = l.edge();
            for (uint32_t z = l.z; z < l.z + e; ++z)
                for (uint32_t y = l.y; y < l.y + e; ++y) {
                    int32_t* row = &L.cellProbe[l.x + size_t(y) * dims_[0] + size_t(z) * layer];
                    std::fill(row, row + e, int32_t(i));
                }
        }
        // Leaves without a probe (minimum size, so one cell each) borrow the first probe above
        // them in their column; a cell between that already borrowed names the same probe.
        for (size_t i = 0; i < n; ++i) {
            if (L.valid[i]) continue;
            const OctreeLeaf& l = leaves[i];
            const size_t cell = l.x + size_t(l.y) * dims_[0] + size_t(l.z) * layer;
            for (uint32_t y = l.y + 1; y < dims_[1]; ++y) {
                const int32_t above = L.cellProbe[l.x + size_t(y) * dims_[0] + size_t(l.z) * layer];
                if (above >= 0 && L.valid[size_t(above)]) {
                    L.cellProbe[cell] = above;
                    t.probe[i] = LeafProbe::Borrowed;
                    break;
                }
            }
        }
        for (size_t i = 0; i < n; ++i) {
            t.moved += t.probe[i] == LeafProbe::Moved;
            t.borrowed += t.probe[i] == LeafProbe::Borrowed;
            t.dropped += t.probe[i] == LeafProbe::Dropped;
        }
        t.uniformProbes = uniformProbes();
        t.leaves = std::move(leaves);
        L.octree = std::move(t);
        return L;
    }

    // Cells whose centre is above the terrain: what a uniform grid at the minimum size keeps.
    size_t uniformProbes() const {
        size_t count = 0;
        for (uint32_t z = 0; z < dims_[2]; ++z)
            for (uint32_t x = 0; x < dims_[0]; ++x) {
                const OctreeLeaf column{x, 0, z, 0};
                const glm::vec3 c = centre(column);
                const float ground = hf_.surfaceHeight(c.x, c.z);
                for (uint32_t y = 0; y < dims_[1]; ++y)
                    count += centre(OctreeLeaf{x, y, z, 0}).y > ground;
            }
        return count;
    }

    void checkBudget(const ProbeLayout& L, const char* what) const {
        checkRefinementBudget(v_, L, what, "adaptive.min_cell_size or adaptive.surface_cell_size");
    }

private:
    const Range& range(const OctreeLeaf& n) const {
        const auto& d = pyramidDims_[n.level];
        return pyramid_[n.level][size_t(n.z >> n.level) * d[0] + (n.x >> n.level)];
    }

    // Level 0: the exact range over each minimum-cell column; level l: over 2^l x 2^l columns.
    void buildColumnRanges() {
        pyramid_.resize(size_t(levels_) + 1);
        pyramidDims_.resize(size_t(levels_) + 1);
        pyramidDims_[0] = {dims_[0], dims_[2]};
        pyramid_[0].resize(size_t(dims_[0]) * dims_[2]);
        tbb::parallel_for(uint32_t(0), dims_[2], [&](uint32_t z) {
            for (uint32_t x = 0; x < dims_[0]; ++x) {
                const double x0 = origin_.x + m_ * x, z0 = origin_.z + m_ * z;
                const SurfaceRange r = surfaceRange(hf_, x0, x0 + m_, z0, z0 + m_);
                pyramid_[0][size_t(z) * dims_[0] + x] = {r.lo, r.hi};
            }
        });
        for (int l = 1; l <= levels_; ++l) {
            const auto& fd = pyramidDims_[size_t(l) - 1];
            const std::array<uint32_t, 2> cd{(fd[0] + 1) / 2, (fd[1] + 1) / 2};
            pyramidDims_[size_t(l)] = cd;
            std::vector<Range>& coarse = pyramid_[size_t(l)];
            const std::vector<Range>& fine = pyramid_[size_t(l) - 1];
            coarse.assign(size_t(cd[0]) * cd[1], Range{});
            for (uint32_t z = 0; z < cd[1]; ++z)
                for (uint32_t x = 0; x < cd[0]; ++x)
                    for (uint32_t dz = 0; dz < 2; ++dz)
                        for (uint32_t dx = 0; dx < 2; ++dx)
                            if (2 * x + dx < fd[0] && 2 * z + dz < fd[1])
                                coarse[size_t(z) * cd[0] + x].add(
                                    fine[size_t(2 * z + dz) * fd[0] + 2 * x + dx]);
        }
    }

    const Heightfield& hf_;
    const ProbeVolumeSettings& v_;
    double m_ = 1.0, band_ = 0.0, share_ = 0.25;
    int levels_ = 0, surfaceLevel_ = 0;
    glm::dvec3 origin_{0.0};
    double dimsD_[3] = {1, 1, 1};
    std::array<uint32_t, 3> dims_{1, 1, 1};
    std::vector<std::vector<Range>> pyramid_;
    std::vector<std::array<uint32_t, 2>> pyramidDims_;
};

// The surface quadtree of one volume (docs/lighting.md, "Surface placement"): squares from
// max_cell_size down to min_cell_size tiling the terrain footprint, one probe per leaf
// height_offset above the triangle surface at its centre (probeAboveSurface, as a terrain grid
// places its probes). Leaves are OctreeLeaf squares with y = 0. The .shprobe grid is the
// footprint in minimum cells from the lowest ground to above the highest probe; each column's
// cells with any part above the terrain name the probe of the leaf over it, as a terrain grid's
// columns name their nearest probe.
class Quadtree {
public:
    static constexpr size_t kChildren = 4;
    Quadtree(const ProbeVolumeSettings& v, const Heightfield& hf) : hf_(hf), v_(v) {
        const std::string where = "probe_volumes '" + v.name + "'";
        const AdaptiveVolumeSettings& a = v.adaptive;
        if (!(v.heightOffset > 0.0))
            throw PlacementError(where + ": height_offset = " + num(v.heightOffset) +
                                 " must be above 0 for surface placement (its probes stand that far above the ground)");
        origin_ = glm::dvec3(hf.minX(), hf.minHeight(), hf.minZ());
        m_ = a.minCellSize ? *a.minCellSize : autoSurfaceMinCell(hf, v.heightOffset);
        levels_ = levelsBetween(where, m_, a.maxCellSize ? *a.maxCellSize : autoSurfaceMaxCell(hf, m_),
                                a.minCellSize.has_value());
        const double spanX = double(hf.maxX()) - hf.minX(), spanZ = double(hf.maxZ()) - hf.minZ();
        const double nx = std::max(1.0, std::ceil(spanX / m_ - 1e-6)), nz = std::max(1.0, std::ceil(spanZ / m_ - 1e-6));
        const double ny = std::ceil((double(hf.maxHeight()) + v.heightOffset - origin_.y) / m_ - 1e-4) + 1.0;
        if (nx * ny * nz > double(kMaxOccupancyCells))
            throw PlacementError(where + ": occupancy grid of " + whole(nx * ny * nz) + " cells (" + whole(nx) + " x " +
                                 whole(ny) + " x " + whole(nz) + " of " + num(m_) + " m) exceeds " +
                                 std::to_string(kMaxOccupancyCells) + "; raise adaptive.min_cell_size");
        dims_ = {uint32_t(nx), 1, uint32_t(nz)};
        lowest_.resize(size_t(dims_[0]) * dims_[2]);
        tbb::parallel_for(uint32_t(0), dims_[2], [&](uint32_t z) {
            for (uint32_t x = 0; x < dims_[0]; ++x) {
                const double x0 = origin_.x + m_ * x, z0 = origin_.z + m_ * z;
                lowest_[size_t(z) * dims_[0] + x] = surfaceRange(hf_, x0, x0 + m_, z0, z0 + m_).lo;
            }
        });
    }

    double maxCell() const { return m_ * std::exp2(levels_); }

    // The probe of a leaf (and the refinement's trial for a child): over its centre.
    glm::vec3 trial(const OctreeLeaf& n) const {
        const double h = 0.5 * double(n.edge());
        float lift = 0.0f;
        return probeAboveSurface(hf_, float(origin_.x + m_ * (n.x + h)), float(origin_.z + m_ * (n.z + h)),
                                 v_.heightOffset, lift);
    }
    bool aboveSurface(const glm::vec3& p) const { return p.y > hf_.surfaceHeight(p.x, p.z); }
    std::array<OctreeLeaf, 4> children(const OctreeLeaf& n) const {
        std::array<OctreeLeaf, 4> c;
        const uint32_t h = n.edge() / 2;
        for (uint32_t i = 0; i < 4; ++i) c[i] = {n.x + (i & 1) * h, 0, n.z + ((i >> 1) & 1) * h, uint8_t(n.level - 1)};
        return c;
    }
    // A square sticking out of the footprint splits (never at the minimum: the footprint is
    // whole minimum cells); one wholly outside is none.
    void visit(const OctreeLeaf& n, std::vector<OctreeLeaf>& out, size_t& split) const {
        if (n.x >= dims_[0] || n.z >= dims_[2]) return;
        if (n.x + n.edge() > dims_[0] || n.z + n.edge() > dims_[2]) {
            for (const OctreeLeaf& c : children(n)) visit(c, out, split);
            return;
        }
        out.push_back(n);
    }
    std::vector<OctreeLeaf> build(size_t& split) const {
        const uint32_t root = 1u << levels_;
        std::vector<OctreeLeaf> leaves;
        for (uint32_t z = 0; z < dims_[2]; z += root)
            for (uint32_t x = 0; x < dims_[0]; x += root) visit(OctreeLeaf{x, 0, z, uint8_t(levels_)}, leaves, split);
        return leaves;
    }
    LeafProbe resolve(const OctreeLeaf& n, glm::vec3& p) const {
        p = trial(n);
        return aboveSurface(p) ? LeafProbe::Centre : LeafProbe::Dropped;
    }

    ProbeLayout layout(std::vector<OctreeLeaf> leaves, size_t) const {
        std::sort(leaves.begin(), leaves.end(), [&](const OctreeLeaf& a, const OctreeLeaf& b) {
            return flatIndex(a, dims_) < flatIndex(b, dims_);
        });
        ProbeLayout L;
        const size_t n = leaves.size();
        L.positions.resize(n);
        L.valid.resize(n);
        L.probeKeys.resize(n);
        AdaptiveOctree t;
        t.surface = true;
        t.heightOffset = v_.heightOffset;
        t.minCell = m_;
        t.maxCell = maxCell();
        t.surfaceCell = m_;
        t.levels = levels_;
        t.probe.resize(n);
        std::vector<float> lifts(n, 0.0f);
        tbb::parallel_for(size_t(0), n, [&](size_t i) {
            const double h = 0.5 * double(leaves[i].edge());
            L.positions[i] = probeAboveSurface(hf_, float(origin_.x + m_ * (leaves[i].x + h)),
                                               float(origin_.z + m_ * (leaves[i].z + h)), v_.heightOffset, lifts[i]);
            t.probe[i] = aboveSurface(L.positions[i]) ? LeafProbe::Centre : LeafProbe::Dropped;
            L.valid[i] = t.probe[i] != LeafProbe::Dropped;
            L.probeKeys[i] = octreeLeafKey(leaves[i]);
        });
        float top = hf_.maxHeight() + float(v_.heightOffset);
        for (size_t i = 0; i < n; ++i) {
            top = std::max(top, L.positions[i].y);
            L.liftedForClearance += lifts[i] > 0.0f;
            L.maxLift = std::max(L.maxLift, lifts[i]);
            t.dropped += !L.valid[i];
        }
        const uint32_t ny = uint32_t(std::ceil((double(top) - origin_.y) / m_ - 1e-4) + 1.0);
        L.cellDims = {dims_[0], std::max(ny, 1u), dims_[2]};
        L.probeDims = {int(L.cellDims[0]), int(L.cellDims[1]), int(L.cellDims[2])};
        L.spacing = glm::vec3(float(m_));
        L.fallbackBlendDistance = v_.fallbackBlendDistance ? float(*v_.fallbackBlendDistance) : 2.0f * float(m_);
        L.cellSize = float(m_);
        L.cellOrigin = glm::vec3(origin_);
        const size_t layer = size_t(L.cellDims[0]) * L.cellDims[1];
        L.cellProbe.assign(layer * L.cellDims[2], -1);
        for (size_t i = 0; i < n; ++i) {
            if (!L.valid[i]) continue;
            const OctreeLeaf& l = leaves[i];
            for (uint32_t z = l.z; z < l.z + l.edge(); ++z)
                for (uint32_t x = l.x; x < l.x + l.edge(); ++x) {
                    const float lowest = lowest_[size_t(z) * dims_[0] + x];
                    for (uint32_t y = 0; y < L.cellDims[1]; ++y)
                        if (origin_.y + m_ * double(y + 1) > double(lowest))
                            L.cellProbe[x + size_t(y) * L.cellDims[0] + size_t(z) * layer] = int32_t(i);
                }
        }
        t.uniformProbes = size_t(dims_[0]) * dims_[2];
        t.leaves = std::move(leaves);
        L.octree = std::move(t);
        return L;
    }

    void checkBudget(const ProbeLayout& L, const char* what) const {
        checkRefinementBudget(v_, L, what, "adaptive.min_cell_size or adaptive.max_cell_size");
    }

private:
    const Heightfield& hf_;
    const ProbeVolumeSettings& v_;
    double m_ = 1.0;
    int levels_ = 0;
    glm::dvec3 origin_{0.0};
    std::array<uint32_t, 3> dims_{1, 1, 1};  // footprint in minimum cells (y unused)
    std::vector<float> lowest_;              // lowest surface over each minimum-cell column
};

struct BakedProbe {
    glm::vec3 position{0.0f};
    sh::ShRgb sh;
    float standardError = 0.0f;
    float fromBelow = 0.0f;
    uint32_t rays = 0;
};

// Bakes, through `baker`, every probe of `L` that `store` lacks at its position.
uint64_t bakeMissing(const ProbeLayout& L, const ProbeBaker& baker,
                     std::unordered_map<uint64_t, BakedProbe>& store) {
    std::vector<glm::vec3> positions;
    std::vector<uint64_t> keys;
    for (size_t i = 0; i < L.positions.size(); ++i) {
        if (!L.valid[i]) continue;
        const auto it = store.find(L.probeKeys[i]);
        if (it != store.end() && it->second.position == L.positions[i]) continue;
        positions.push_back(L.positions[i]);
        keys.push_back(L.probeKeys[i]);
    }
    if (positions.empty()) return 0;
    const ProbeBake b = baker(positions, keys);
    for (size_t i = 0; i < positions.size(); ++i)
        store[keys[i]] = {positions[i], b.sh[i], b.standardError[i], b.fromBelowShare[i], b.raysPerProbe[i]};
    return b.rays;
}

}  // namespace

ProbeBaker seededBaker(const BakeLighting& lighting, const IrradianceCache* cache, int bounces,
                       const ProbeRays& rays, uint64_t seed, const BakeControl& control, bool reference) {
    return [&lighting, cache, bounces, rays, seed, control, reference](
               const std::vector<glm::vec3>& positions, const std::vector<uint64_t>& keys) {
        std::vector<uint64_t> seeds(keys.size());
        for (size_t i = 0; i < keys.size(); ++i) seeds[i] = seed ^ keys[i];
        const std::vector<uint8_t> valid(positions.size(), 1);
        return reference ? referenceProbesSeeded(lighting, bounces, positions, valid, rays, seeds, control)
                         : bakeProbesSeeded(lighting, cache, bounces, positions, valid, rays, seeds, control);
    };
}

ProbeBaker deringedBaker(ProbeBaker baker, bool dering, uint64_t* rays) {
    return [baker = std::move(baker), dering, rays](const std::vector<glm::vec3>& p, const std::vector<uint64_t>& k) {
        ProbeBake t = baker(p, k);
        if (rays) *rays += t.rays;
        if (dering)
            for (auto& s : t.sh) sh::deringIrradiance(s);
        return t;
    };
}

uint64_t octreeLeafKey(const OctreeLeaf& l) {
    uint64_t k = splitmix64(0x0C7EE1EAFull ^ l.x);
    k = splitmix64(k ^ l.y);
    k = splitmix64(k ^ l.z);
    return splitmix64(k ^ l.level);
}

namespace {

// The first layout of a tree (no refinement), checked against the budgets.
template <class Tree>
ProbeLayout firstLayout(const Tree& tree, size_t& split) {
    std::vector<OctreeLeaf> leaves = tree.build(split);
    ProbeLayout L = tree.layout(std::move(leaves), split);
    tree.checkBudget(L, Tree::kChildren == 8 ? "the surface band alone" : "the largest squares alone");
    return L;
}

// Bakes a tree's probes and, with a tolerance, refines it by error (bakeAdaptive).
template <class Tree>
AdaptiveBake bakeTree(const Tree& tree, const ProbeVolumeSettings& v, const ProbeBaker& baker,
                      const std::function<void(int, size_t)>& onRound) {
    size_t split = 0;
    AdaptiveBake out;
    out.layout = firstLayout(tree, split);
    std::unordered_map<uint64_t, BakedProbe> store;
    uint64_t rays = bakeMissing(out.layout, baker, store);

    if (v.adaptive.tolerance) {
        AdaptiveRefinement ref;
        ref.tolerance = *v.adaptive.tolerance;
        const std::optional<int> budgetProbes = v.adaptive.maxProbes ? v.adaptive.maxProbes : kMaxVolumeProbes;
        const auto& budgetBytes = v.adaptive.maxBytes;
        std::unordered_set<uint64_t> kept;  // tested leaves that stay
        for (int round = 1;; ++round) {
            // The layout's leaves are sorted, so everything below follows a fixed order.
            const std::vector<OctreeLeaf>& current = out.layout.octree->leaves;
            std::vector<size_t> candidates;
            for (size_t i = 0; i < current.size(); ++i)
                if (current[i].level > 0 && !kept.count(out.layout.probeKeys[i]))
                    candidates.push_back(i);
            if (candidates.empty()) break;
            ref.rounds = round;
            ref.leavesTested += candidates.size();
            if (onRound) onRound(round, candidates.size());

            std::vector<glm::vec3> positions;
            std::vector<uint64_t> keys;
            for (size_t i : candidates)
                for (const OctreeLeaf& c : tree.children(current[i])) {
                    positions.push_back(tree.trial(c));
                    keys.push_back(octreeLeafKey(c));
                }
            const ProbeBake octants = baker(positions, keys);
            rays += octants.rays;
            ref.octantProbes += positions.size();

            struct Scored {
                size_t leaf;
                double error;
            };
            std::vector<Scored> failing;
            for (size_t k = 0; k < candidates.size(); ++k) {
                const size_t i = candidates[k];
                const sh::ShRgb& own = store.at(out.layout.probeKeys[i]).sh;
                double error = 0.0;
                // An octant whose centre is in the terrain sees it from inside: no light an
                // interpolated point above the surface receives, so it is not a test of the leaf.
                for (size_t o = 0; o < Tree::kChildren; ++o)
                    if (tree.aboveSurface(positions[Tree::kChildren * k + o]))
                        error = std::max(error, double(relativeIrradianceError(own, octants.sh[Tree::kChildren * k + o])));
                if (error > ref.tolerance) {
                    failing.push_back({k, error});
                } else {
                    kept.insert(out.layout.probeKeys[i]);
                    ref.worstKeptError = std::max(ref.worstKeptError, error);
                }
            }
            std::stable_sort(failing.begin(), failing.end(),
                             [](const Scored& a, const Scored& b) { return a.error > b.error; });

            size_t probes = out.layout.validCount();
            const uint64_t cells = out.layout.cellProbe.size();
            std::vector<uint8_t> splitLeaf(current.size(), 0);
            std::vector<OctreeLeaf> added;
            for (size_t f = 0; f < failing.size(); ++f) {
                const size_t k = failing[f].leaf, i = candidates[k];
                std::vector<OctreeLeaf> children;
                size_t unused = 0;
                for (const OctreeLeaf& c : tree.children(current[i])) tree.visit(c, children, unused);
                size_t childProbes = 0, octantsKept = 0;
                for (const OctreeLeaf& c : children) {
                    glm::vec3 p;
                    const LeafProbe state = tree.resolve(c, p);
                    childProbes += state != LeafProbe::Dropped;
                    octantsKept += state == LeafProbe::Centre && c.level + 1 == current[i].level;
                }
                const size_t next = probes - 1 + childProbes;
                if ((budgetProbes && next > size_t(*budgetProbes)) ||
                    (budgetBytes && 48 + 160 * uint64_t(next) + 4 * cells > uint64_t(*budgetBytes))) {
                    ref.budgetReached = true;
                    ref.leavesOverTolerance = failing.size() - f;
                    break;
                }
                probes = next;
                splitLeaf[i] = 1;
                ++ref.leavesSplit;
                ref.octantProbesKept += octantsKept;
                split += unused;
                // The octant bakes become the children's probes.
                for (size_t o = 0; o < Tree::kChildren; ++o)
                    store[keys[Tree::kChildren * k + o]] = {positions[Tree::kChildren * k + o], octants.sh[Tree::kChildren * k + o],
                                              octants.standardError[Tree::kChildren * k + o],
                                              octants.fromBelowShare[Tree::kChildren * k + o],
                                              octants.raysPerProbe[Tree::kChildren * k + o]};
                added.insert(added.end(), children.begin(), children.end());
            }
            if (!added.empty()) {
                std::vector<OctreeLeaf> next;
                for (size_t i = 0; i < current.size(); ++i)
                    if (!splitLeaf[i]) next.push_back(current[i]);
                next.insert(next.end(), added.begin(), added.end());
                out.layout = tree.layout(std::move(next), split);
                rays += bakeMissing(out.layout, baker, store);
            }
            if (ref.budgetReached || added.empty()) break;
        }
        out.refinement = ref;
    }

    const size_t n = out.layout.positions.size();
    out.bake = ProbeBake(n);
    for (size_t i = 0; i < n; ++i) {
        if (!out.layout.valid[i]) continue;
        const BakedProbe& b = store.at(out.layout.probeKeys[i]);
        out.bake.sh[i] = b.sh;
        out.bake.standardError[i] = b.standardError;
        out.bake.fromBelowShare[i] = b.fromBelow;
        out.bake.raysPerProbe[i] = b.rays;
    }
    out.bake.rays = rays;
    return out;
}

}  // namespace

ProbeLayout placeAdaptive(const ProbeVolumeSettings& v, const Heightfield& hf) {
    size_t split = 0;
    return v.placement == ProbePlacement::Surface ? firstLayout(Quadtree(v, hf), split) : firstLayout(Octree(v, hf), split);
}

AdaptiveBake bakeAdaptive(const ProbeVolumeSettings& v, const Heightfield& hf, const ProbeBaker& baker,
                          const std::function<void(int, size_t)>& onRound) {
    if (v.placement == ProbePlacement::Surface) return bakeTree(Quadtree(v, hf), v, baker, onRound);
    return bakeTree(Octree(v, hf), v, baker, onRound);
}

bool interpolateProbes(const ProbeLayout& L, const std::vector<sh::ShRgb>& shs, const glm::vec3& p,
                       sh::ShRgb& out) {
    // Lattice of cell centres: cell i's centre sits at lattice coordinate i.
    const glm::dvec3 g = (glm::dvec3(p) - glm::dvec3(L.cellOrigin)) / double(L.cellSize) - 0.5;
    const glm::dvec3 base = glm::floor(g);
    const glm::dvec3 f = g - base;
    sh::ShRgb acc;
    double total = 0.0;
    for (int corner = 0; corner < 8; ++corner) {
        const int dx = corner & 1, dy = (corner >> 1) & 1, dz = (corner >> 2) & 1;
        const double cx = base.x + dx, cy = base.y + dy, cz = base.z + dz;
        if (cx < 0 || cy < 0 || cz < 0 || cx >= L.cellDims[0] || cy >= L.cellDims[1] ||
            cz >= L.cellDims[2])
            continue;
        const int32_t probe = L.cellProbe[size_t(cx) + size_t(cy) * L.cellDims[0] +
                                          size_t(cz) * L.cellDims[0] * L.cellDims[1]];
        if (probe < 0) continue;
        const double w = (dx ? f.x : 1.0 - f.x) * (dy ? f.y : 1.0 - f.y) * (dz ? f.z : 1.0 - f.z);
        if (w <= 0.0) continue;
        sh::ShRgb term = shs[size_t(probe)];
        term *= float(w);
        acc += term;
        total += w;
    }
    if (total <= 0.0) return false;
    acc *= float(1.0 / total);
    out = acc;
    return true;
}

InterpolationError measureInterpolationError(const ProbeLayout& L, const std::vector<sh::ShRgb>& shs,
                                             const Heightfield& hf, const ProbeBaker& baker,
                                             int count, uint64_t seed,
                                             std::optional<double> tolerance) {
    InterpolationError e;
    const glm::dvec3 lo(L.cellOrigin);
    const glm::dvec3 extent = double(L.cellSize) *
                              glm::dvec3(L.cellDims[0], L.cellDims[1], L.cellDims[2]);
    Rng rng(seed ^ 0x1E7E5A4D5A3Dull);
    std::vector<glm::vec3> points;
    const bool layer = L.octree && L.octree->surface;
    for (int attempt = 0; attempt < 64 * count && int(points.size()) < count; ++attempt) {
        glm::vec3 p(lo + extent * glm::dvec3(rng.next(), rng.next(), rng.next()));
        // A surface volume models the layer its probes stand in: up to twice their height.
        if (layer) p.y = hf.surfaceHeight(p.x, p.z) + float(2.0 * L.octree->heightOffset * rng.next());
        if (p.y > hf.surfaceHeight(p.x, p.z)) points.push_back(p);
    }
    if (points.empty()) return e;
    std::vector<uint64_t> keys(points.size());
    for (size_t i = 0; i < points.size(); ++i)
        keys[i] = splitmix64(seed ^ 0x5A3D1E7Eull ^ (uint64_t(i) * 0x9E3779B97F4A7C15ull));
    const ProbeBake truth = baker(points, keys);
    const double floor = interpolationErrorFloor(truth.sh);
    for (size_t i = 0; i < points.size(); ++i) {
        sh::ShRgb value;
        if (!interpolateProbes(L, shs, points[i], value)) {
            ++e.uncovered;
            continue;
        }
        e.positions.push_back(points[i]);
        e.errors.push_back(relativeIrradianceError(value, truth.sh[i], floor));
    }
    e.points = e.errors.size();
    if (e.errors.empty()) return e;
    const Spread s = spreadOf(e.errors);
    e.mean = s.mean;
    e.p95 = s.p95;
    e.max = s.max;
    size_t within = 0;
    for (float x : e.errors) within += tolerance && double(x) <= *tolerance;
    if (tolerance) e.withinTolerance = double(within) / double(e.errors.size());
    return e;
}

}  // namespace terralux
