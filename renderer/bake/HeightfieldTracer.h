#pragma once
// Exact ray casting against the Heightfield triangle surface (and its skirt), accelerated by a
// maximum-height quadtree over the cells: the "maximum mipmap" of Tevs, Ihrke and Seidel,
// "Maximum Mipmaps for Fast, Accurate, and Scalable Dynamic Height Field Rendering" (I3D 2008).
//
// Surface: inside the footprint, the two triangles per cell of Heightfield.h. With the skirt on,
// outside it the height at (x, z) is the mesh height at the nearest border point (exactly
// Heightfield::surfaceHeight): the border profile extruded outward along the four edges and a
// level plane at the corner height in the four corner quadrants. That surface is infinite, so
// with the skirt on every ray with dir.y < 0 hits something. With the skirt off, rays that leave
// the footprint escape. Neither variant has vertical walls: every normal faces up (y > 0).
//
// All geometry is evaluated in double precision in grid space (u = x / cellSizeX + (width-1)/2,
// the same mapping as Heightfield::surfaceHeight), so vertices sit on exact integers.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "terrain/Heightfield.h"

namespace terralux {

struct RayHit {
    float t = 0;             // distance along the unit direction
    glm::vec3 position{};    // origin + t * dir
    glm::vec3 normal{};      // unit geometric normal of the surface hit, facing up (y > 0)
    bool onTerrain = false;  // true: a mesh triangle inside the footprint; false: the skirt
};

// One ray of a batch: as intersect()'s arguments.
struct TraceRay {
    glm::vec3 origin{};
    glm::vec3 dir{};  // unit length
    float tMax = INFINITY;
};

class HeightfieldTracer {
public:
    // Which build of the walk traces: the baseline (any x86-64) or the same code compiled for
    // x86-64-v3 (AVX2, BMI1/2, FMA: Haswell, Zen and later), 1-6 % faster on the bench's rays.
    // Neither fuses multiply-adds (HeightfieldTracer.cpp is built without contraction), so the
    // two round alike and a bake is the same bytes on either. kAuto takes x86-64-v3 where the
    // CPU has it, unless the environment pins TERRALUX_TRACER_KERNEL=baseline.
    enum class Kernel { kAuto, kBaseline, kX86_64_v3 };
    struct Options {
        bool skirt = true;
        Kernel kernel = Kernel::kAuto;  // kX86_64_v3 on a CPU without it falls back to baseline
        // The terrain around this grid at a coarser resolution (a tile's far halo, docs/farm.md),
        // or null. A ray traces `beyond` over the part of it outside this grid's footprint (before
        // it enters and after it leaves) and this grid over the footprint, so the nearest hit of
        // either is the hit; beyond's hits count as the skirt's (onTerrain false). Needs the skirt
        // off (beyond has its own); must outlive this tracer.
        const HeightfieldTracer* beyond = nullptr;
    };
    // Whether this CPU (and OS) can run the x86-64-v3 kernel.
    static bool cpuHasX86_64_v3();
    // The kernel kAuto resolves to in this process: "x86-64-v3" or "baseline".
    static const char* autoKernelName();

    // Keeps a reference to hf: it must outlive the tracer and not change while the tracer lives.
    // (Two constructors rather than "Options opt = {}": a nested type's default member
    // initializers cannot be used by a default argument inside the enclosing class, CWG 1397.)
    explicit HeightfieldTracer(const Heightfield& hf);
    HeightfieldTracer(const Heightfield& hf, Options opt);

    // First hit with minDistance(origin) < t <= tMax along a unit-length dir (tMax may be
    // +infinity). false: the ray escapes (sky). Thread-safe: the tracer is immutable.
    bool intersect(const glm::vec3& origin, const glm::vec3& dir, float tMax, RayHit& hit) const;
    // Whether any hit exists in the same range; cheaper than intersect when only visibility
    // matters.
    bool occluded(const glm::vec3& origin, const glm::vec3& dir, float tMax) const;
    // A batch: found[i] (blocked[i]) and hits[i] are what intersect (occluded) gives for rays[i],
    // bit for bit. The rays walk one after another, but ray i + 4 is set up and its start cell
    // prefetched while ray i walks, hiding the cold start cell that dominates a short
    // incoherent ray.
    // The spans of results hold at least rays.size() entries.
    void intersect(std::span<const TraceRay> rays, std::span<RayHit> hits, std::span<uint8_t> found) const;
    void occluded(std::span<const TraceRay> rays, std::span<uint8_t> blocked) const;

    const Heightfield& heightfield() const { return *hf_; }
    const Options& options() const { return opt_; }
    // The kernel this tracer runs (never kAuto).
    Kernel kernel() const { return kernel_; }
    // Whether the ground reaches (x, z): inside the footprint, on the skirt, or over `beyond`.
    bool reaches(float x, float z) const {
        return opt_.skirt || hf_->contains(x, z) || (opt_.beyond && opt_.beyond->reaches(x, z));
    }
    // Number of quadtree levels (level 0 holds one node per cell).
    int levelCount() const { return int(levels_.size()); }

    // Hits at t <= minDistance(origin) are ignored, so that a ray leaving a surface point cannot
    // hit that point again through rounding: 1e-6 of the origin's largest coordinate (8 to 16
    // float ulps of it) plus 1e-6 m. Callers should lift secondary-ray origins off the surface
    // by a few times that along the normal, e.g. 1e-5 * max|coordinate| + 1 mm.
    static float minDistance(const glm::vec3& origin) {
        const float m = std::max({std::fabs(origin.x), std::fabs(origin.y), std::fabs(origin.z)});
        return 1e-6f * (1.0f + m);
    }

private:
    struct Level {
        int nx = 0, nz = 0;  // nodes along X and Z
        size_t offset = 0;   // first node in maxQ_ (unused for level 0)
    };
    struct Walk;
    enum class Step : uint8_t { kRunning, kHit, kMiss };
    bool start(Walk& w, const glm::vec3& origin, const glm::vec3& dir, float tMax) const;
    template <bool AnyHit>
    Step step(Walk& w, RayHit* hit) const;
    void prefetch(const Walk& w) const;
    template <bool AnyHit>
    bool trace(const glm::vec3& origin, const glm::vec3& dir, float tMax, RayHit* hit) const;
    // The ray's t over this grid's footprint, [ta, tb]; false when it never crosses it.
    bool footprintSpan(const glm::vec3& origin, const glm::vec3& dir, double& ta, double& tb) const;
    // The walk over this grid alone, in this tracer's kernel.
    template <bool AnyHit>
    bool traceHere(const glm::vec3& origin, const glm::vec3& dir, float tMax, RayHit* hit) const;
    // `beyond` along t in (t0, t1], the hit's t counted from the origin; `leaving`: t0 is where
    // the ray leaves the footprint, and it goes on at its height over the ground there.
    template <bool AnyHit>
    bool traceBeyond(const glm::vec3& origin, const glm::vec3& dir, double t0, float t1, bool leaving,
                     RayHit* hit) const;
    // With `beyond`: the ray's segments before and after the footprint, given whether (and
    // where) the footprint's walk hit.
    template <bool AnyHit>
    bool throughBeyond(const glm::vec3& origin, const glm::vec3& dir, float tMax, bool hereFound, RayHit* hit) const;
    template <bool AnyHit>
    void traceBatch(const TraceRay* rays, size_t n, RayHit* hits, uint8_t* found) const;
    template <bool AnyHit>
    void batchBaseline(const TraceRay* rays, size_t n, RayHit* hits, uint8_t* found) const;
    template <bool AnyHit>
    void batchX86_64_v3(const TraceRay* rays, size_t n, RayHit* hits, uint8_t* found) const;
    // trace<> compiled for each kernel (HeightfieldTracer.cpp inlines it into both).
    template <bool AnyHit>
    bool traceBaseline(const glm::vec3& origin, const glm::vec3& dir, float tMax,
                       RayHit* hit) const;
    template <bool AnyHit>
    bool traceX86_64_v3(const glm::vec3& origin, const glm::vec3& dir, float tMax,
                        RayHit* hit) const;

    const Heightfield* hf_;
    Options opt_;
    Kernel kernel_ = Kernel::kBaseline;
    int cellsX_ = 1, cellsZ_ = 1;  // at least 1: a one-vertex-wide grid has one zero-width cell
    bool hasTriangles_ = false;    // width >= 2 and depth >= 2
    double invCellX_ = 1, invCellZ_ = 1;
    std::vector<Level> levels_;  // levels_[0]: cells; levels_.back(): the single root node
    // Max vertex height under each node of levels >= 1 (the skirt only repeats border heights),
    // quantized upward: qBase_ + q * qStep_ >= true max + cullMargin_. 16 bits keep the
    // levels of a 1201^2 DEM near 1 MB, cache-resident next to the float heights, which the
    // cells (level 0) read directly.
    std::vector<uint16_t> maxQ_;
    double qBase_ = 0, qStep_ = 1;
    double cullMargin_ = 0;  // absorbs rounding in the culling comparisons
    double rootMax_ = 0;     // the highest vertex plus the margin: a rising ray above it escapes
};

// Reference: every triangle (and, when skirt is true, every skirt piece) tested one by one with
// a double-precision Moller-Trumbore test in world space, nearest hit in (minDistance, tMax].
bool intersectBruteForce(const Heightfield& hf, bool skirt, const glm::vec3& origin,
                         const glm::vec3& dir, float tMax, RayHit& hit);

// Baseline: fixed-step ray march (one step per min(cellSizeX, cellSizeZ) of t) over
// Heightfield::surfaceHeight (so the skirt is always on), stopping at the first sample below the
// surface and refining by bisection to 1e-4 m; gives up after 1e8 steps. Can step over thin
// ridges and so miss hits or find later ones; kept as the benchmarks' baseline.
bool intersectRayMarch(const Heightfield& hf, const glm::vec3& origin, const glm::vec3& dir,
                       float tMax, RayHit& hit);

}  // namespace terralux
