#include "bake/HeightfieldTracer.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

// The walk and its cell tests are inlined into one function per kernel, so that each is compiled
// for that kernel's instruction set; only the (rare) skirt pieces and the final normal stay
// shared, baseline code.
#if defined(__GNUC__)
#define TLX_WALK_INLINE [[gnu::always_inline]] inline
#else
#define TLX_WALK_INLINE inline
#endif
#if (defined(__x86_64__) || defined(_M_X64)) && defined(__GNUC__)
#define TLX_HAVE_X86_64_V3 1
#define TLX_TARGET_X86_64_V3 __attribute__((target("arch=x86-64-v3")))
#else
#define TLX_HAVE_X86_64_V3 0
#endif

namespace terralux {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Adjacent planar pieces overlap by this much (in cells) in the point-in-piece tests, so a ray
// through a shared edge or vertex cannot slip between them; rounding in those tests is ~1e-11
// cells, and the brute force reference uses the same slack.
constexpr double kEdgeSlack = 1e-7;

// The ray in grid space: u = x / cellSizeX + (width - 1) / 2, v likewise; y and t in metres.
struct GridRay {
    double u0, v0, y0;
    double du, dv, dy;
};

// Slopes (metres per cell along u and v) of the planar piece hit, to build its normal.
struct Piece {
    double gu = 0, gv = 0;
    bool onTerrain = false;
};

// Plane h(u, v) = h0 + (u - uc) * gu + (v - vc) * gv against the ray: t in (tLo, tHi] and the
// hit's position relative to (uc, vc). The height difference ray - plane is linear in t, so
// this is exact up to rounding. A parallel ray gives t = inf or NaN, which the range rejects.
TLX_WALK_INLINE bool planeHit(const GridRay& r, double uc, double vc, double h0, double gu, double gv,
                     double tLo, double tHi, double& t, double& fu, double& fv) {
    const double a = r.u0 - uc, b = r.v0 - vc;
    const double f0 = r.y0 - h0 - a * gu - b * gv;
    const double f1 = r.dy - r.du * gu - r.dv * gv;
    t = -f0 / f1;
    if (!(t > tLo && t <= tHi))
        return false;
    fu = a + t * r.du;
    fv = b + t * r.dv;
    return true;
}

// The two triangles of cell (c, r): updates tBest / piece with the nearest hit in
// (tLo, tBest]. hRC = height of vertex (c or c + 1, r or r + 1).
TLX_WALK_INLINE bool trianglesHit(const GridRay& ray, int c, int r, double h00, double h10, double h01,
                         double h11, double tLo, double& tBest, Piece& piece) {
    constexpr double e = kEdgeSlack;
    bool found = false;
    double t, fu, fv;
    // Triangle A: (c, r), (c, r+1), (c+1, r+1), where fu <= fv.
    if (planeHit(ray, c, r, h00, h11 - h01, h01 - h00, tLo, tBest, t, fu, fv) && fu >= -e &&
        fv <= 1 + e && fu <= fv + e) {
        tBest = t;
        piece = {h11 - h01, h01 - h00, true};
        found = true;
    }
    // Triangle B: (c, r), (c+1, r+1), (c+1, r), where fu > fv.
    if (planeHit(ray, c, r, h00, h10 - h00, h11 - h10, tLo, tBest, t, fu, fv) && fv >= -e &&
        fu <= 1 + e && fv <= fu + e) {
        tBest = t;
        piece = {h10 - h00, h11 - h10, true};
        found = true;
    }
    return found;
}

// The skirt pieces that extend border cell (c, r) outward, as trianglesHit. c1 = min(c + 1,
// width - 1), r1 likewise (a one-vertex-wide grid has zero-width cells).
bool skirtHit(const GridRay& ray, int cellsX, int cellsZ, int c, int r, int c1, int r1, double h00,
              double h10, double h01, double h11, double tLo, double& tBest, Piece& piece) {
    constexpr double e = kEdgeSlack;
    bool found = false;
    double t, fu, fv;
    auto take = [&](double gu, double gv) {
        tBest = t;
        piece = {gu, gv, false};
        found = true;
    };
    const bool left = c == 0, right = c == cellsX - 1, top = r == 0, bottom = r == cellsZ - 1;
    // Edge strips: the border segment of this cell extruded outward, level across the edge.
    if (r1 > r) {
        if (left && planeHit(ray, c, r, h00, 0, h01 - h00, tLo, tBest, t, fu, fv) && fu <= e &&
            fv >= -e && fv <= 1 + e)
            take(0, h01 - h00);
        if (right && planeHit(ray, c1, r, h10, 0, h11 - h10, tLo, tBest, t, fu, fv) && fu >= -e &&
            fv >= -e && fv <= 1 + e)
            take(0, h11 - h10);
    }
    if (c1 > c) {
        if (top && planeHit(ray, c, r, h00, h10 - h00, 0, tLo, tBest, t, fu, fv) && fv <= e &&
            fu >= -e && fu <= 1 + e)
            take(h10 - h00, 0);
        if (bottom && planeHit(ray, c, r1, h01, h11 - h01, 0, tLo, tBest, t, fu, fv) && fv >= -e &&
            fu >= -e && fu <= 1 + e)
            take(h11 - h01, 0);
    }
    // Corner quadrants: level at the corner vertex height.
    if (left && top && planeHit(ray, c, r, h00, 0, 0, tLo, tBest, t, fu, fv) && fu <= e && fv <= e)
        take(0, 0);
    if (right && top && planeHit(ray, c1, r, h10, 0, 0, tLo, tBest, t, fu, fv) && fu >= -e &&
        fv <= e)
        take(0, 0);
    if (left && bottom && planeHit(ray, c, r1, h01, 0, 0, tLo, tBest, t, fu, fv) && fu <= e &&
        fv >= -e)
        take(0, 0);
    if (right && bottom && planeHit(ray, c1, r1, h11, 0, 0, tLo, tBest, t, fu, fv) && fu >= -e &&
        fv >= -e)
        take(0, 0);
    return found;
}

// Cell index along one axis for grid coordinate p, clamped to the grid (border cells extend to
// infinity outward).
TLX_WALK_INLINE int startIndex(double p, int cells) {
    return int(std::clamp(std::floor(p), 0.0, double(cells - 1)));
}

// One axis of the footprint's slab test: narrows [lo, hi], a ray's t, to where its grid
// coordinate p0 + t·dp lies in [0, extent]; hi becomes -inf where it never does.
TLX_WALK_INLINE void clipToSlab(double p0, double dp, double extent, double& lo, double& hi) {
    if (dp == 0) {
        if (p0 < 0 || p0 > extent)
            hi = -kInf;
        return;
    }
    double a = (0 - p0) / dp, b = (extent - p0) / dp;
    if (a > b)
        std::swap(a, b);
    lo = std::max(lo, a);
    hi = std::min(hi, b);
}

glm::vec3 pieceNormal(const Piece& p, double cellX, double cellZ) {
    const double nx = -p.gu / cellX, nz = -p.gv / cellZ;
    const double inv = 1.0 / std::sqrt(nx * nx + 1.0 + nz * nz);
    return {float(nx * inv), float(inv), float(nz * inv)};
}

}  // namespace

HeightfieldTracer::HeightfieldTracer(const Heightfield& hf) : HeightfieldTracer(hf, Options{}) {}

bool HeightfieldTracer::cpuHasX86_64_v3() {
#if TLX_HAVE_X86_64_V3
    // The features the kernel's code uses beyond the baseline; every CPU that has these four
    // (Haswell, Excavator and later) has the rest of x86-64-v3. GCC's check of AVX includes the
    // OS saving the YMM registers.
    static const bool has = [] {
        __builtin_cpu_init();
        return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
               __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2");
    }();
    return has;
#else
    return false;
#endif
}

namespace {
HeightfieldTracer::Kernel autoKernel() {
    static const HeightfieldTracer::Kernel k = [] {
        const char* pin = std::getenv("TERRALUX_TRACER_KERNEL");
        if (pin && std::strcmp(pin, "baseline") == 0)
            return HeightfieldTracer::Kernel::kBaseline;
        return HeightfieldTracer::cpuHasX86_64_v3() ? HeightfieldTracer::Kernel::kX86_64_v3
                                                    : HeightfieldTracer::Kernel::kBaseline;
    }();
    return k;
}
}  // namespace

const char* HeightfieldTracer::autoKernelName() {
    return autoKernel() == Kernel::kX86_64_v3 ? "x86-64-v3" : "baseline";
}

HeightfieldTracer::HeightfieldTracer(const Heightfield& hf, Options opt) : hf_(&hf), opt_(opt) {
    if (opt.beyond && opt.skirt)
        throw std::invalid_argument("HeightfieldTracer: terrain beyond the footprint needs the skirt off");
    kernel_ = opt.kernel == Kernel::kAuto ? autoKernel()
              : opt.kernel == Kernel::kX86_64_v3 && cpuHasX86_64_v3() ? Kernel::kX86_64_v3
                                                                      : Kernel::kBaseline;
    const int w = hf.width(), d = hf.depth();
    invCellX_ = 1.0 / hf.cellSizeX();
    invCellZ_ = 1.0 / hf.cellSizeZ();
    cellsX_ = std::max(w - 1, 1);
    cellsZ_ = std::max(d - 1, 1);
    hasTriangles_ = w >= 2 && d >= 2;

    // Level sizes: halve (rounding up) until a single root node remains.
    int nx = cellsX_, nz = cellsZ_;
    size_t total = 0;
    levels_.push_back({nx, nz, 0});
    while (nx > 1 || nz > 1) {
        nx = (nx + 1) / 2;
        nz = (nz + 1) / 2;
        levels_.push_back({nx, nz, total});
        total += size_t(nx) * size_t(nz);
    }

    // Culling compares double ray heights with these bounds; the margin dwarfs the rounding of
    // either side, and only costs a little culling.
    cullMargin_ = 1e-6 * (1.0 + std::max(std::fabs(hf.minHeight()), std::fabs(hf.maxHeight())));
    rootMax_ = double(hf.maxHeight()) + cullMargin_;
    qBase_ = hf.minHeight();
    qStep_ = std::max(double(hf.maxHeight()) - double(hf.minHeight()), 1.0) / 60000.0;
    auto quantize = [&](double m) {
        const double q = std::ceil((m + cullMargin_ - qBase_) / qStep_) + 1.0;
        return uint16_t(std::clamp(q, 0.0, 65535.0));
    };
    maxQ_.assign(total, 0);
    if (levels_.size() < 2)
        return;

    // Level 1 straight from the heights (each node: up to 3 x 3 vertices), then 2 x 2 reductions
    // of the quantized values (monotonic, so still upper bounds).
    const float* h = hf.heights().data();
    const Level& l1 = levels_[1];
    for (int z = 0; z < l1.nz; ++z) {
        const int r0 = 2 * z, r1 = std::min(2 * z + 2, d - 1);
        for (int x = 0; x < l1.nx; ++x) {
            const int c0 = 2 * x, c1 = std::min(2 * x + 2, w - 1);
            float m = h[size_t(r0) * size_t(w) + size_t(c0)];
            for (int r = r0; r <= r1; ++r)
                for (int c = c0; c <= c1; ++c)
                    m = std::max(m, h[size_t(r) * size_t(w) + size_t(c)]);
            maxQ_[l1.offset + size_t(z) * size_t(l1.nx) + size_t(x)] = quantize(m);
        }
    }
    for (size_t l = 2; l < levels_.size(); ++l) {
        const Level& fine = levels_[l - 1];
        const Level& coarse = levels_[l];
        const uint16_t* src = maxQ_.data() + fine.offset;
        uint16_t* dst = maxQ_.data() + coarse.offset;
        for (int z = 0; z < coarse.nz; ++z) {
            const int z0 = 2 * z, z1 = std::min(2 * z + 1, fine.nz - 1);
            for (int x = 0; x < coarse.nx; ++x) {
                const int x0 = 2 * x, x1 = std::min(2 * x + 1, fine.nx - 1);
                const uint16_t* a = src + size_t(z0) * size_t(fine.nx);
                const uint16_t* b = src + size_t(z1) * size_t(fine.nx);
                dst[size_t(z) * size_t(coarse.nx) + size_t(x)] =
                    std::max(std::max(a[x0], a[x1]), std::max(b[x0], b[x1]));
            }
        }
    }
}

// Stackless max-mipmap traversal (Tevs et al. 2008, sec. 4): keep the current node (level, ix,
// iz) and the ray parameter t at which the ray is inside it. If the ray's lowest height over
// the node's t interval is above the node max, step to the next node at the same level and go
// up a level (see the end of the loop); else descend into the child holding the ray at t, or
// at a cell test its triangles. Node boundaries are integer cell indices and every boundary's
// t is computed by one expression, so stepping, ascending and descending agree exactly on
// which node holds the ray, and every step moves forward: the walk ends. Border nodes extend
// to infinity outward, which is where the skirt lives; with the skirt off, t is clipped to the
// footprint instead.
// One ray's walk between two node visits: what the traversal below keeps from one visit to the
// next, so that a batch can interleave several walks (and prefetch each one's next node while
// the others run) and a single ray can run the same visits back to back.
struct HeightfieldTracer::Walk {
    GridRay ray;
    glm::vec3 origin, dir;
    double tLo, t, tEnd, invDu, invDv;
    int lvl, ix, iz;
    // Per axis: negU when u decreases along the ray; exit boundary = (index + exit) << lvl.
    bool negU, negV, rising;
};

// Stackless max-mipmap traversal (Tevs et al. 2008, sec. 4): keep the current node (level, ix,
// iz) and the ray parameter t at which the ray is inside it. If the ray's lowest height over
// the node's t interval is above the node max, step to the next node at the same level and go
// up a level (see the end of step()); else descend into the child holding the ray at t, or
// at a cell test its triangles. Node boundaries are integer cell indices and every boundary's
// t is computed by one expression, so stepping, ascending and descending agree exactly on
// which node holds the ray, and every step moves forward: the walk ends. Border nodes extend
// to infinity outward, which is where the skirt lives; with the skirt off, t is clipped to the
// footprint instead.
TLX_WALK_INLINE bool HeightfieldTracer::start(Walk& w, const glm::vec3& o, const glm::vec3& dir, float tMax) const {
    // NaN or infinite input would make the cell index below undefined.
    if (!std::isfinite(double(o.x) + o.y + o.z + dir.x + dir.y + dir.z))
        return false;
    const Heightfield& hf = *hf_;
    GridRay& ray = w.ray;
    w.origin = o;
    w.dir = dir;
    // Heightfield's own mapping (a division, then an add), so that a ray through a vertex lands
    // on its integer grid coordinate: a multiply by the rounded reciprocal can leave it a
    // rounding error off, outside the footprint at a border vertex.
    ray.u0 = hf.colOf(o.x);
    ray.v0 = hf.rowOf(o.z);
    ray.y0 = o.y;
    ray.du = double(dir.x) * invCellX_;
    ray.dv = double(dir.z) * invCellZ_;
    ray.dy = dir.y;

    w.tLo = minDistance(o);
    double t = w.tLo;
    // At most FLT_MAX: hit.t must fit a float, and t = inf (a ray parallel to a level skirt
    // piece) is no hit.
    double tEnd = std::min(double(tMax), double(FLT_MAX));
    if (!(t < tEnd))
        return false;

    if (!opt_.skirt) {
        if (!hasTriangles_)
            return false;
        clipToSlab(ray.u0, ray.du, hf.width() - 1, t, tEnd);
        clipToSlab(ray.v0, ray.dv, hf.depth() - 1, t, tEnd);
        if (!(t <= tEnd))
            return false;
    }
    w.t = t;
    w.tEnd = tEnd;

    // A ray with du = 0 is walked as increasing u with 1 / du = DBL_MAX: its crossings then lie
    // at t = 0 (u0 on the line) or at |t| far beyond FLT_MAX >= tEnd, so "which side of u = k"
    // comes out as u0 >= k with no separate case in the walk.
    w.negU = ray.du < 0;
    w.negV = ray.dv < 0;
    w.invDu = ray.du != 0 ? 1.0 / ray.du : DBL_MAX;
    w.invDv = ray.dv != 0 ? 1.0 / ray.dv : DBL_MAX;
    w.rising = ray.dy >= 0;
    // Whether the ray at t is on the high side of u = k (v = k), consistent with step()'s crossings.
    auto highU = [&](int k) { return (t >= (double(k) - ray.u0) * w.invDu) != w.negU; };
    auto highV = [&](int k) { return (t >= (double(k) - ray.v0) * w.invDv) != w.negV; };

    // Start at the cell holding the ray at t (most rays cast from the surface end within a few
    // cells, and a walk down from the root would cost a dependent cache miss per level). The
    // floor() guess is settled against the crossings so that it agrees with stepping.
    int ix = startIndex(ray.u0 + t * ray.du, cellsX_);
    int iz = startIndex(ray.v0 + t * ray.dv, cellsZ_);
    while (ix > 0 && !highU(ix))
        --ix;
    while (ix + 1 < cellsX_ && highU(ix + 1))
        ++ix;
    while (iz > 0 && !highV(iz))
        --iz;
    while (iz + 1 < cellsZ_ && highV(iz + 1))
        ++iz;
    w.lvl = 0;
    w.ix = ix;
    w.iz = iz;
    return true;
}

// Asks for the memory the walk's next visit reads: a cell's two height rows, or a node's bound.
TLX_WALK_INLINE void HeightfieldTracer::prefetch(const Walk& w) const {
#if defined(__GNUC__)
    if (w.lvl == 0) {
        const size_t width = size_t(hf_->width());
        const float* row0 = hf_->heights().data() + size_t(w.iz) * width + size_t(w.ix);
        __builtin_prefetch(row0);
        __builtin_prefetch(row0 + (w.iz + 1 < hf_->depth() ? width : 0));
    } else {
        const Level& L = levels_[size_t(w.lvl)];
        __builtin_prefetch(maxQ_.data() + L.offset + size_t(w.iz) * size_t(L.nx) + size_t(w.ix));
    }
#else
    (void)w;
#endif
}

// One node visit: a hit, the walk ended without one, or the walk moved to its next node.
template <bool AnyHit>
TLX_WALK_INLINE HeightfieldTracer::Step HeightfieldTracer::step(Walk& w, RayHit* hit) const {
    const Heightfield& hf = *hf_;
    const GridRay& ray = w.ray;
    const int lvl = w.lvl, ix = w.ix, iz = w.iz;
    const double t = w.t, tEnd = w.tEnd;
    // t at which the ray crosses grid line u = k (v = k): the single expression used everywhere.
    auto crossU = [&](int k) { return (double(k) - ray.u0) * w.invDu; };
    auto crossV = [&](int k) { return (double(k) - ray.v0) * w.invDv; };
    auto highU = [&](int k) { return (t >= crossU(k)) != w.negU; };
    auto highV = [&](int k) { return (t >= crossV(k)) != w.negV; };

    // Where the ray leaves the node; the outermost nodes reach to infinity (the skirt).
    const int ku = (ix + (w.negU ? 0 : 1)) << lvl, kv = (iz + (w.negV ? 0 : 1)) << lvl;
    const double tx = ku > 0 && ku < cellsX_ ? crossU(ku) : kInf;
    const double tz = kv > 0 && kv < cellsZ_ ? crossV(kv) : kInf;
    const double tExit = std::min(std::min(tx, tz), tEnd);
    const double yLow = ray.y0 + ray.dy * (w.rising ? t : tExit);
    if (lvl == 0) {
        // A cell: its own four heights bound it (and its skirt pieces), no stored level.
        const int wd = hf.width(), d = hf.depth();
        const int c1 = std::min(ix + 1, wd - 1), r1 = std::min(iz + 1, d - 1);
        const float* heights = hf.heights().data();
        const float* row0 = heights + size_t(iz) * size_t(wd);
        const float* row1 = heights + size_t(r1) * size_t(wd);
        const float f00 = row0[ix], f10 = row0[c1], f01 = row1[ix], f11 = row1[c1];
        const double cellMax = std::max(std::max(f00, f10), std::max(f01, f11));
        // The cell's pieces cannot be hit outside its box (up to kEdgeSlack), so the first
        // cell with a hit holds the nearest one.
        if (yLow <= cellMax + cullMargin_) {
            double tHit = tEnd;
            Piece piece;
            bool found = hasTriangles_ && trianglesHit(ray, ix, iz, f00, f10, f01, f11, w.tLo, tHit, piece);
            if (opt_.skirt && (ix == 0 || iz == 0 || ix == cellsX_ - 1 || iz == cellsZ_ - 1))
                found |= skirtHit(ray, cellsX_, cellsZ_, ix, iz, c1, r1, f00, f10, f01, f11, w.tLo, tHit, piece);
            if (found) {
                if constexpr (!AnyHit) {
                    hit->t = float(tHit);
                    hit->position = w.origin + hit->t * w.dir;
                    hit->normal = pieceNormal(piece, hf.cellSizeX(), hf.cellSizeZ());
                    hit->onTerrain = piece.onTerrain;
                }
                return Step::kHit;
            }
        }
    } else {
        const Level& L = levels_[size_t(lvl)];
        const double nodeMax = qBase_ + qStep_ * maxQ_[L.offset + size_t(iz) * size_t(L.nx) + size_t(ix)];
        if (yLow <= nodeMax) {
            // Descend into the child holding the ray at t.
            const int cl = lvl - 1;
            int cx = ix << 1, cz = iz << 1;
            const Level& C = levels_[size_t(cl)];
            if (cx + 1 < C.nx)
                cx += highU((cx + 1) << cl);
            if (cz + 1 < C.nz)
                cz += highV((cz + 1) << cl);
            w.lvl = cl;
            w.ix = cx;
            w.iz = cz;
            return Step::kRunning;
        }
    }
    if (tExit >= tEnd || (w.rising && ray.y0 + ray.dy * tExit > rootMax_))
        return Step::kMiss;
    // Step to the next node; go one level up when it lies in another parent or, for a rising
    // ray (which only gets higher), always, as the parent may now be cleared too.
    w.t = tExit;
    const int nx = ix + (tx <= tExit ? (w.negU ? -1 : 1) : 0);
    const int nz = iz + (tz <= tExit ? (w.negV ? -1 : 1) : 0);
    const int up = lvl < int(levels_.size()) - 1 && (w.rising || ((ix ^ nx) | (iz ^ nz)) > 1);
    w.lvl = lvl + up;
    w.ix = nx >> up;
    w.iz = nz >> up;
    return Step::kRunning;
}

template <bool AnyHit>
TLX_WALK_INLINE bool HeightfieldTracer::trace(const glm::vec3& o, const glm::vec3& dir, float tMax,
                                              RayHit* hit) const {
    Walk w;
    if (!start(w, o, dir, tMax))
        return false;
    for (;;) {
        const Step s = step<AnyHit>(w, hit);
        if (s != Step::kRunning)
            return s == Step::kHit;
    }
}

// The batch, ahead-started: ray i + kAhead is set up (no memory read) and its start cell
// prefetched while ray i walks in registers, so the cold start cell, the costliest read of a
// short walk, arrives before it is needed. Every ray's visits are the single-ray walk's.
template <bool AnyHit>
TLX_WALK_INLINE void HeightfieldTracer::traceBatch(const TraceRay* rays, size_t n, RayHit* hits,
                                                   uint8_t* found) const {
    constexpr size_t kAhead = 4;
    Walk ring[kAhead];
    bool live[kAhead] = {};
    auto begin = [&](size_t k) {
        const size_t slot = k % kAhead;
        live[slot] = start(ring[slot], rays[k].origin, rays[k].dir, rays[k].tMax);
        if (live[slot])
            prefetch(ring[slot]);
    };
    for (size_t k = 0; k < std::min(n, kAhead); ++k)
        begin(k);
    for (size_t i = 0; i < n; ++i) {
        const size_t slot = i % kAhead;
        Step s = Step::kMiss;
        if (live[slot]) {
            Walk& w = ring[slot];
            while ((s = step<AnyHit>(w, AnyHit ? nullptr : hits + i)) == Step::kRunning) {
            }
        }
        found[i] = s == Step::kHit;
        if (i + kAhead < n)
            begin(i + kAhead);
    }
}

template <bool AnyHit>
bool HeightfieldTracer::traceBaseline(const glm::vec3& o, const glm::vec3& dir, float tMax,
                                      RayHit* hit) const {
    return trace<AnyHit>(o, dir, tMax, hit);
}

template <bool AnyHit>
#if TLX_HAVE_X86_64_V3
TLX_TARGET_X86_64_V3
#endif
bool HeightfieldTracer::traceX86_64_v3(const glm::vec3& o, const glm::vec3& dir, float tMax,
                                       RayHit* hit) const {
    return trace<AnyHit>(o, dir, tMax, hit);
}

template <bool AnyHit>
void HeightfieldTracer::batchBaseline(const TraceRay* rays, size_t n, RayHit* hits, uint8_t* found) const {
    traceBatch<AnyHit>(rays, n, hits, found);
}

template <bool AnyHit>
#if TLX_HAVE_X86_64_V3
TLX_TARGET_X86_64_V3
#endif
void HeightfieldTracer::batchX86_64_v3(const TraceRay* rays, size_t n, RayHit* hits, uint8_t* found) const {
    traceBatch<AnyHit>(rays, n, hits, found);
}

bool HeightfieldTracer::footprintSpan(const glm::vec3& o, const glm::vec3& dir, double& ta, double& tb) const {
    if (!std::isfinite(double(o.x) + o.y + o.z + dir.x + dir.y + dir.z))
        return false;
    ta = -kInf;
    tb = kInf;
    // In grid space, as start() clips a ray without the skirt, so the walk over the footprint
    // and the segments beyond it meet at the same t.
    clipToSlab(hf_->colOf(o.x), double(dir.x) * invCellX_, hf_->width() - 1, ta, tb);
    clipToSlab(hf_->rowOf(o.z), double(dir.z) * invCellZ_, hf_->depth() - 1, ta, tb);
    return ta <= tb;
}

template <bool AnyHit>
bool HeightfieldTracer::traceHere(const glm::vec3& o, const glm::vec3& dir, float tMax, RayHit* hit) const {
    return kernel_ == Kernel::kX86_64_v3 ? traceX86_64_v3<AnyHit>(o, dir, tMax, hit)
                                         : traceBaseline<AnyHit>(o, dir, tMax, hit);
}

template <bool AnyHit>
bool HeightfieldTracer::traceBeyond(const glm::vec3& o, const glm::vec3& dir, double t0, float t1, bool leaving,
                                    RayHit* hit) const {
    if (!(t0 < double(t1)))
        return false;
    if (!leaving) {
        if (AnyHit)
            return opt_.beyond->occluded(o, dir, t1);
        if (!opt_.beyond->intersect(o, dir, t1, *hit))
            return false;
        hit->onTerrain = false;
        return true;
    }
    // From the point where the ray leaves the footprint: `beyond` holds the footprint too, at
    // its own resolution, and must not see it. Its coarser surface stands above or below this
    // grid's at the seam, so the ray goes on at the height over the ground it had there: a ray
    // just over this grid would otherwise start under the coarser ground and end at the seam.
    // (A ray from the footprint's very edge leaves it at t0 = 0.)
    glm::vec3 p = o + float(t0) * dir;
    if (!std::isfinite(p.x + p.y + p.z))
        return false;
    const float lift = opt_.beyond->heightfield().surfaceHeight(p.x, p.z) - hf_->surfaceHeight(p.x, p.z);
    p.y += lift;
    const float tMax = std::isinf(t1) ? t1 : float(double(t1) - t0);
    if (AnyHit)
        return opt_.beyond->occluded(p, dir, tMax);
    if (!opt_.beyond->intersect(p, dir, tMax, *hit))
        return false;
    hit->t = float(t0 + double(hit->t));
    hit->position.y -= lift;
    hit->onTerrain = false;
    return true;
}

template <bool AnyHit>
bool HeightfieldTracer::throughBeyond(const glm::vec3& o, const glm::vec3& dir, float tMax, bool hereFound,
                                      RayHit* hit) const {
    if (!(tMax > 0.0f))
        return hereFound;
    // An origin on the footprint's edge (a probe on a region's border, a cache point lifted off
    // the ground there) counts as on it whichever side rounding or the lift puts it: within
    // twice what a secondary ray's origin is lifted by (1e-5 of its largest coordinate + 1 cm).
    const float m = std::max({std::fabs(o.x), std::fabs(o.y), std::fabs(o.z)});
    const double tolerance = 2.0 * (1e-5 * double(m) + 1e-2);
    const double outside = std::max({double(hf_->minX()) - o.x, double(o.x) - hf_->maxX(),
                                     double(hf_->minZ()) - o.z, double(o.z) - hf_->maxZ(), 0.0});
    const bool onEdge = outside <= tolerance;
    const double edge = minDistance(o);
    double ta = 0, tb = 0;
    // A ray that never crosses the footprint ahead of its origin is beyond's alone; from the
    // edge, it leaves at once.
    if (!footprintSpan(o, dir, ta, tb) || tb < -edge)
        return traceBeyond<AnyHit>(o, dir, 0.0, tMax, onEdge, hit);
    // Before the footprint: nearer than any hit over it. (From the edge there is none: the ray
    // is already over the footprint's ground.)
    if (ta > edge && !onEdge) {
        RayHit before;
        if (traceBeyond<AnyHit>(o, dir, 0.0, float(std::min(ta, double(tMax))), false, AnyHit ? nullptr : &before)) {
            if (!AnyHit)
                *hit = before;
            return true;
        }
    }
    if (hereFound)
        return true;
    // Past FLT_MAX no hit can be reported (hit.t is a float).
    return tb < double(tMax) && tb < double(FLT_MAX) &&
           traceBeyond<AnyHit>(o, dir, std::max(tb, 0.0), tMax, true, hit);
}

void HeightfieldTracer::intersect(std::span<const TraceRay> rays, std::span<RayHit> hits,
                                  std::span<uint8_t> found) const {
    if (hits.size() < rays.size() || found.size() < rays.size())
        throw std::invalid_argument("HeightfieldTracer::intersect: " + std::to_string(rays.size()) +
                                    " rays need as many hits and flags");
    if (kernel_ == Kernel::kX86_64_v3)
        batchX86_64_v3<false>(rays.data(), rays.size(), hits.data(), found.data());
    else
        batchBaseline<false>(rays.data(), rays.size(), hits.data(), found.data());
    if (opt_.beyond)
        for (size_t i = 0; i < rays.size(); ++i)
            found[i] = throughBeyond<false>(rays[i].origin, rays[i].dir, rays[i].tMax, found[i], &hits[i]);
}

void HeightfieldTracer::occluded(std::span<const TraceRay> rays, std::span<uint8_t> blocked) const {
    if (blocked.size() < rays.size())
        throw std::invalid_argument("HeightfieldTracer::occluded: " + std::to_string(rays.size()) +
                                    " rays need as many flags");
    if (kernel_ == Kernel::kX86_64_v3)
        batchX86_64_v3<true>(rays.data(), rays.size(), nullptr, blocked.data());
    else
        batchBaseline<true>(rays.data(), rays.size(), nullptr, blocked.data());
    if (opt_.beyond)
        for (size_t i = 0; i < rays.size(); ++i)
            blocked[i] = throughBeyond<true>(rays[i].origin, rays[i].dir, rays[i].tMax, blocked[i], nullptr);
}

bool HeightfieldTracer::intersect(const glm::vec3& origin, const glm::vec3& dir, float tMax,
                                  RayHit& hit) const {
    const bool here = traceHere<false>(origin, dir, tMax, &hit);
    return opt_.beyond ? throughBeyond<false>(origin, dir, tMax, here, &hit) : here;
}

bool HeightfieldTracer::occluded(const glm::vec3& origin, const glm::vec3& dir, float tMax) const {
    if (!opt_.beyond)
        return traceHere<true>(origin, dir, tMax, nullptr);
    // The footprint first: most blocked rays of a tile end there.
    return throughBeyond<true>(origin, dir, tMax, traceHere<true>(origin, dir, tMax, nullptr), nullptr);
}

bool intersectBruteForce(const Heightfield& hf, bool skirt, const glm::vec3& origin,
                         const glm::vec3& dir, float tMax, RayHit& hit) {
    using glm::dvec3;
    const int w = hf.width(), d = hf.depth();
    const double cellX = hf.cellSizeX(), cellZ = hf.cellSizeZ();
    const double tLo = HeightfieldTracer::minDistance(origin);
    double best = std::min(double(tMax), double(FLT_MAX));
    if (!(tLo < best))
        return false;
    const dvec3 O(origin), D(dir);
    auto X = [&](int c) { return (c - hf.originCol()) * cellX; };
    auto Z = [&](int r) { return (r - hf.originRow()) * cellZ; };
    auto V = [&](int c, int r) { return dvec3(X(c), double(hf.at(c, r)), Z(r)); };
    constexpr double e = kEdgeSlack;

    bool found = false;
    dvec3 bestNormal(0, 1, 0);
    bool bestTerrain = false;
    auto take = [&](double t, dvec3 n, bool terrain) {
        best = t;
        bestNormal = n.y < 0 ? -n : n;
        bestTerrain = terrain;
        found = true;
    };
    // Moller & Trumbore, "Fast, Minimum Storage Ray/Triangle Intersection" (JGT 1997), in
    // double, no back-face culling.
    auto triangle = [&](const dvec3& a, const dvec3& b, const dvec3& c) {
        const dvec3 e1 = b - a, e2 = c - a;
        const dvec3 p = glm::cross(D, e2);
        const double det = glm::dot(e1, p);
        if (det == 0)
            return;
        const double inv = 1.0 / det;
        const dvec3 s = O - a;
        const double bu = glm::dot(s, p) * inv;
        if (!(bu >= -e && bu <= 1 + e))
            return;
        const dvec3 q = glm::cross(s, e1);
        const double bv = glm::dot(D, q) * inv;
        if (!(bv >= -e && bu + bv <= 1 + e))
            return;
        const double t = glm::dot(e2, q) * inv;
        if (t > tLo && t <= best)
            take(t, glm::cross(e1, e2), true);
    };
    for (int r = 0; r + 1 < d; ++r)
        for (int c = 0; c + 1 < w; ++c) {
            triangle(V(c, r), V(c, r + 1), V(c + 1, r + 1));
            triangle(V(c, r), V(c + 1, r + 1), V(c + 1, r));
        }

    if (skirt) {
        // Half-infinite strip: border segment p0-p1 swept along the horizontal unit vector out.
        auto strip = [&](const dvec3& p0, const dvec3& p1, const dvec3& out, double cell) {
            const dvec3 edge = p1 - p0;
            const dvec3 n = glm::cross(edge, out);
            const double den = glm::dot(D, n);
            if (den == 0)
                return;
            const double t = glm::dot(p0 - O, n) / den;
            if (!(t > tLo && t <= best))
                return;
            const dvec3 rel = O + t * D - p0;
            const double a = glm::dot(rel, edge) / glm::dot(edge, edge);
            if (a >= -e && a <= 1 + e && glm::dot(rel, out) >= -e * cell)
                take(t, n, false);
        };
        if (d >= 2)
            for (int r = 0; r + 1 < d; ++r) {
                strip(V(0, r), V(0, r + 1), dvec3(-1, 0, 0), cellX);
                strip(V(w - 1, r), V(w - 1, r + 1), dvec3(1, 0, 0), cellX);
            }
        if (w >= 2)
            for (int c = 0; c + 1 < w; ++c) {
                strip(V(c, 0), V(c + 1, 0), dvec3(0, 0, -1), cellZ);
                strip(V(c, d - 1), V(c + 1, d - 1), dvec3(0, 0, 1), cellZ);
            }
        // Corner quadrants, level at the corner height; sx, sz = outward signs.
        auto corner = [&](int c, int r, double sx, double sz) {
            if (D.y == 0)
                return;
            const dvec3 p = V(c, r);
            const double t = (p.y - O.y) / D.y;
            if (!(t > tLo && t <= best))
                return;
            const dvec3 q = O + t * D;
            if ((q.x - p.x) * sx >= -e * cellX && (q.z - p.z) * sz >= -e * cellZ)
                take(t, dvec3(0, 1, 0), false);
        };
        corner(0, 0, -1, -1);
        corner(w - 1, 0, 1, -1);
        corner(0, d - 1, -1, 1);
        corner(w - 1, d - 1, 1, 1);
    }
    if (!found)
        return false;
    hit.t = float(best);
    hit.position = origin + hit.t * dir;
    hit.normal = glm::vec3(glm::normalize(bestNormal));
    hit.onTerrain = bestTerrain;
    return true;
}

bool intersectRayMarch(const Heightfield& hf, const glm::vec3& origin, const glm::vec3& dir,
                       float tMax, RayHit& hit) {
    const double step = std::min(hf.cellSizeX(), hf.cellSizeZ());
    const double lo = hf.minHeight(), hi = hf.maxHeight();
    const glm::dvec3 O(origin), D(dir);
    double t0 = HeightfieldTracer::minDistance(origin);
    double tEnd = std::min(double(tMax), double(FLT_MAX));
    // Only the slab lo <= y <= hi can hold a crossing: start at its top, stop at its bottom
    // (below lo the ray is under the surface everywhere) or when rising out of it.
    if (D.y > 0) {
        tEnd = std::min(tEnd, (hi - O.y) / D.y);
    } else if (D.y < 0) {
        t0 = std::max(t0, (hi - O.y) / D.y);
        tEnd = std::min(tEnd, (lo - O.y) / D.y);
    } else {
        if (O.y > hi)
            return false;
        // Level ray inside the slab: march until well past the footprint.
        const double ex = hf.maxX() - hf.minX(), ez = hf.maxZ() - hf.minZ();
        const double diag = std::sqrt(ex * ex + ez * ez);
        tEnd = std::min(tEnd, std::hypot(O.x - 0.5 * (hf.minX() + hf.maxX()), O.z - 0.5 * (hf.minZ() + hf.maxZ())) + 2 * diag + step);
    }
    if (!(t0 <= tEnd))
        return false;
    tEnd = std::min(tEnd, t0 + 1e8 * step);  // near-level rays: give up after 1e8 steps
    auto below = [&](double t) {
        const glm::dvec3 p = O + t * D;
        return p.y <= double(hf.surfaceHeight(float(p.x), float(p.z)));
    };
    double ta = t0, tb = t0;
    bool crossed = below(t0);
    while (!crossed && tb < tEnd) {
        ta = tb;
        tb = std::min(tb + step, tEnd);
        crossed = below(tb);
    }
    if (!crossed)
        return false;
    while (tb - ta > 1e-4) {
        const double tm = 0.5 * (ta + tb);
        (below(tm) ? tb : ta) = tm;
    }
    hit.t = float(tb);
    hit.position = origin + hit.t * dir;
    hit.normal = hf.surfaceNormal(hit.position.x, hit.position.z);
    hit.onTerrain = hf.contains(hit.position.x, hit.position.z);
    return true;
}

}  // namespace terralux
