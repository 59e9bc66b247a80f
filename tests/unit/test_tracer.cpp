// HeightfieldTracer against the brute-force reference and against analytic answers.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <random>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include "bake/HeightfieldTracer.h"
#include "terrain/Heightfield.h"

namespace terralux {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Multi-octave value noise plus spikes and pits, so cells have steep, thin features.
Heightfield makeRoughDem(int w, int d, double cellX, double cellZ, float relief, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    std::vector<float> h(size_t(w) * size_t(d), 0.0f);
    float amp = relief;
    for (int period = 16; period >= 1; period /= 2, amp *= 0.5f) {
        const int gw = w / period + 2, gd = d / period + 2;
        std::vector<float> lattice(size_t(gw) * size_t(gd));
        for (float& v : lattice)
            v = u01(rng);
        for (int r = 0; r < d; ++r)
            for (int c = 0; c < w; ++c) {
                const int lc = c / period, lr = r / period;
                const float fx = float(c % period) / float(period);
                const float fz = float(r % period) / float(period);
                auto L = [&](int i, int j) { return lattice[size_t(j) * size_t(gw) + size_t(i)]; };
                const float top = L(lc, lr) + fx * (L(lc + 1, lr) - L(lc, lr));
                const float bot = L(lc, lr + 1) + fx * (L(lc + 1, lr + 1) - L(lc, lr + 1));
                h[size_t(r) * size_t(w) + size_t(c)] += amp * (top + fz * (bot - top));
            }
    }
    std::uniform_int_distribution<size_t> pick(0, h.size() - 1);
    for (size_t i = 0; i < h.size() / 20 + 1; ++i)
        h[pick(rng)] += relief * (2.0f * u01(rng) - 0.5f);
    return Heightfield(w, d, cellX, cellZ, std::move(h));
}

glm::vec3 randomDir(std::mt19937& rng) {
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (;;) {
        const glm::vec3 v(u(rng), u(rng), u(rng));
        const float l2 = glm::dot(v, v);
        if (l2 > 1e-4f && l2 <= 1.0f)
            return v / std::sqrt(l2);
    }
}

struct Stats {
    long rays = 0, hits = 0, hitMiss = 0, tMismatch = 0, normalMismatch = 0, terrainMismatch = 0,
         occludedMismatch = 0, badHitPoint = 0;
    long disagreements() const {
        return hitMiss + tMismatch + normalMismatch + terrainMismatch + occludedMismatch +
               badHitPoint;
    }
    void add(const Stats& o) {
        rays += o.rays;
        hits += o.hits;
        hitMiss += o.hitMiss;
        tMismatch += o.tMismatch;
        normalMismatch += o.normalMismatch;
        terrainMismatch += o.terrainMismatch;
        occludedMismatch += o.occludedMismatch;
        badHitPoint += o.badHitPoint;
    }
};

std::ostream& operator<<(std::ostream& os, const Stats& s) {
    return os << s.rays << " rays, " << s.hits << " hits; disagreements: hit/miss " << s.hitMiss
              << ", t " << s.tMismatch << ", normal " << s.normalMismatch << ", onTerrain "
              << s.terrainMismatch << ", occluded " << s.occludedMismatch << ", hit point "
              << s.badHitPoint;
}

bool tAgrees(float a, float b) {
    return std::fabs(a - b) <= std::max(1e-3f, 1e-4f * b);
}

// One ray through the tracer and the reference. strict: also compare normal and onTerrain,
// which are ambiguous for rays aimed exactly at an edge or a seam.
void compareRay(const HeightfieldTracer& tracer, const glm::vec3& o, const glm::vec3& dir,
                float tMax, bool strict, Stats& s, const std::string& what) {
    const Heightfield& hf = tracer.heightfield();
    const bool skirt = tracer.options().skirt;
    RayHit a, b;
    const bool ha = tracer.intersect(o, dir, tMax, a);
    const bool hb = intersectBruteForce(hf, skirt, o, dir, tMax, b);
    ++s.rays;
    s.hits += hb;
    auto report = [&](const char* kind) {
        if (s.disagreements() <= 5)
            ADD_FAILURE() << what << ": " << kind << " o=(" << o.x << "," << o.y << "," << o.z
                          << ") d=(" << dir.x << "," << dir.y << "," << dir.z << ") tMax=" << tMax
                          << " tracer " << ha << " t=" << a.t << " brute " << hb << " t=" << b.t;
    };
    if (ha != hb) {
        ++s.hitMiss;
        report("hit/miss");
    } else if (ha) {
        if (!tAgrees(a.t, b.t)) {
            ++s.tMismatch;
            report("t");
        }
        if (strict && glm::dot(a.normal, b.normal) < 0.9999f) {
            ++s.normalMismatch;
            report("normal");
        }
        if (strict && a.onTerrain != b.onTerrain) {
            ++s.terrainMismatch;
            report("onTerrain");
        }
        // The hit lies on the surface it claims, with an up-facing unit normal. Only checked
        // where float positions are fine enough (not for hits tens of kilometres away).
        const glm::vec3 p = a.position;
        const bool inside = hf.contains(p.x, p.z) && hf.width() > 1 && hf.depth() > 1;
        bool pointOk = a.normal.y > 0.0f && std::fabs(glm::length(a.normal) - 1.0f) <= 1e-5f;
        if (strict && a.t < 1e4f) {
            // Float rounding of the position, times the slope, bounds the height error.
            const float slope = glm::length(glm::vec2(a.normal.x, a.normal.z)) / a.normal.y;
            const float posErr = 1e-6f * (std::fabs(p.x) + std::fabs(p.z) + a.t);
            pointOk = pointOk && a.onTerrain == inside &&
                      std::fabs(p.y - hf.surfaceHeight(p.x, p.z)) <= 0.01f + posErr * (1 + slope);
        }
        if (!pointOk) {
            ++s.badHitPoint;
            report("hit point");
        }
    }
    const bool occ = tracer.occluded(o, dir, tMax);
    bool occOk = occ == ha;
    if (ha && a.t > 1.0f) {
        // Any-hit queries just short of and just past the first hit.
        occOk = occOk && !tracer.occluded(o, dir, a.t * 0.999f) &&
                tracer.occluded(o, dir, a.t * 1.001f);
    }
    if (!occOk) {
        ++s.occludedMismatch;
        report("occluded");
    }
}

struct DemCase {
    const char* name;
    int w, d;
    double cellX, cellZ;
    float relief;
    int rays;
};

// 100 000 random rays per skirt setting over these grids.
const DemCase kDems[] = {
    {"17x23 30x45m", 17, 23, 30.0, 45.0, 400.0f, 20000},
    {"64x64 10x10m", 64, 64, 10.0, 10.0, 150.0f, 20000},
    {"37x50 45x30m", 37, 50, 45.0, 30.0, 600.0f, 20000},
    {"33x1 30x45m", 33, 1, 30.0, 45.0, 300.0f, 10000},
    {"1x29 30x45m", 1, 29, 30.0, 45.0, 300.0f, 10000},
    {"2x2 30x45m", 2, 2, 30.0, 45.0, 100.0f, 10000},
    {"1x1", 1, 1, 30.0, 45.0, 100.0f, 10000},
};

// Random origins above the surface, inside the footprint and around it, in full-sphere
// directions; a third of them with a finite tMax.
Stats randomRays(const HeightfieldTracer& tracer, const DemCase& dc, uint32_t seed) {
    const Heightfield& hf = tracer.heightfield();
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    const float ex = std::max(hf.maxX() - hf.minX(), 100.0f);
    const float ez = std::max(hf.maxZ() - hf.minZ(), 100.0f);
    Stats s;
    for (int i = 0; i < dc.rays; ++i) {
        const float x = hf.minX() + (1.6f * u01(rng) - 0.3f) * ex;
        const float z = hf.minZ() + (1.6f * u01(rng) - 0.3f) * ez;
        const float lift = std::pow(10.0f, -2.0f + 5.0f * u01(rng));  // 1 cm .. 1 km
        const glm::vec3 o(x, hf.surfaceHeight(x, z) + lift, z);
        const glm::vec3 dir = randomDir(rng);
        const float tMax = i % 3 == 0 ? 2000.0f * u01(rng) : kInf;
        compareRay(tracer, o, dir, tMax, true, s, dc.name);
    }
    return s;
}

// Grazing, axis-aligned, vertical and diagonal rays, rays through vertices and along grid
// lines, and rays from outside the footprint aimed into it.
Stats specialRays(const HeightfieldTracer& tracer, uint32_t seed) {
    const Heightfield& hf = tracer.heightfield();
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    std::uniform_int_distribution<int> col(0, hf.width() - 1), row(0, hf.depth() - 1);
    const float ex = std::max(hf.maxX() - hf.minX(), 100.0f);
    const float ez = std::max(hf.maxZ() - hf.minZ(), 100.0f);
    auto randomXZ = [&](float& x, float& z) {
        x = hf.minX() + (1.6f * u01(rng) - 0.3f) * ex;
        z = hf.minZ() + (1.6f * u01(rng) - 0.3f) * ez;
    };
    auto above = [&](float x, float z, float lift) {
        return glm::vec3(x, hf.surfaceHeight(x, z) + lift, z);
    };
    auto lift = [&] { return std::pow(10.0f, -2.0f + 4.0f * u01(rng)); };
    const float sign[2] = {-1.0f, 1.0f};
    Stats s;
    for (int i = 0; i < 400; ++i) {
        float x, z;
        randomXZ(x, z);
        const float phi = 6.2831853f * u01(rng);
        const float sy = sign[i & 1];
        // Grazing: |dir.y| in {0, 1e-4, 1e-3}.
        for (float dy : {0.0f, 1e-4f, 1e-3f}) {
            const float c = std::sqrt(1.0f - dy * dy);
            const glm::vec3 dir(c * std::cos(phi), sy * dy, c * std::sin(phi));
            compareRay(tracer, above(x, z, lift()), dir, kInf, true, s, "grazing");
        }
        // Axis-aligned in x or z, random elevation; origin on a grid line every other time.
        const float el = (u01(rng) - 0.5f) * 3.0f;
        const float ce = std::cos(el), se = std::sin(el);
        const float gx = (i & 2) ? hf.xOf(col(rng)) : x;
        const float gz = (i & 2) ? hf.zOf(row(rng)) : z;
        compareRay(tracer, above(gx, z, lift()), {0.0f, se, sy * ce}, kInf, false, s, "axis z");
        compareRay(tracer, above(x, gz, lift()), {sy * ce, se, 0.0f}, kInf, false, s, "axis x");
        // Grazing along a grid line.
        compareRay(tracer, above(gx, z, lift()), {0.0f, -1e-4f, sy * 0.99999999f}, kInf, false, s,
                   "grazing axis");
        // Vertical, at random points, at vertices and at cell-edge midpoints.
        compareRay(tracer, above(x, z, lift()), {0.0f, -1.0f, 0.0f}, kInf, true, s, "vertical");
        compareRay(tracer, above(gx, gz, lift()), {0.0f, -1.0f, 0.0f}, kInf, false, s,
                   "vertical vertex");
        compareRay(tracer, above(gx, gz + 0.5f * float(hf.cellSizeZ()), lift()),
                   {0.0f, -1.0f, 0.0f}, kInf, false, s, "vertical edge");
        compareRay(tracer, above(x, z, lift()), {0.0f, 1.0f, 0.0f}, kInf, true, s, "up");
        // Along the cell diagonal from a vertex, down and up.
        const glm::vec3 diag = glm::normalize(
            glm::vec3(sy * float(hf.cellSizeX()), 2.0f * (u01(rng) - 0.5f) * float(hf.cellSizeX()),
                      sy * float(hf.cellSizeZ())));
        compareRay(tracer, above(hf.xOf(col(rng)), hf.zOf(row(rng)), lift()), diag, kInf, false, s,
                   "diagonal");
        // From outside the footprint, above the skirt, aimed at a point inside it.
        const float side = 1.5f + u01(rng);
        const glm::vec3 from(std::cos(phi) * side * ex, hf.maxHeight() + 200.0f * u01(rng),
                             std::sin(phi) * side * ez);
        const glm::vec3 target(hf.minX() + u01(rng) * (hf.maxX() - hf.minX()),
                               hf.minHeight() + u01(rng) * (hf.maxHeight() - hf.minHeight()),
                               hf.minZ() + u01(rng) * (hf.maxZ() - hf.minZ()));
        compareRay(tracer, from, glm::normalize(target - from), kInf, true, s, "from outside");
        // Lifted off the surface along the normal, leaving it: no self-hits.
        randomXZ(x, z);
        const glm::vec3 n = hf.surfaceNormal(x, z);
        const glm::vec3 p = glm::vec3(x, hf.surfaceHeight(x, z), z) + 0.01f * n;
        glm::vec3 dir = randomDir(rng);
        if (glm::dot(dir, n) < 0)
            dir = -dir;
        compareRay(tracer, p, dir, kInf, true, s, "leaving surface");
    }
    return s;
}

using Kernel = HeightfieldTracer::Kernel;

// The two builds of the walk; x86-64-v3 only where this CPU runs it (elsewhere it would fall back
// to the baseline, which is already on the list).
std::vector<Kernel> kernelsHere() {
    std::vector<Kernel> k{Kernel::kBaseline};
    if (HeightfieldTracer::cpuHasX86_64_v3())
        k.push_back(Kernel::kX86_64_v3);
    return k;
}

const char* kernelName(Kernel k) {
    return k == Kernel::kX86_64_v3 ? "x86-64-v3" : "baseline";
}

void runComparison(bool skirt, uint32_t seedBase, Kernel kernel) {
    Stats total, special;
    uint32_t seed = seedBase;
    std::cout << "[ kernel " << kernelName(kernel) << " ]\n";
    for (const DemCase& dc : kDems) {
        const Heightfield hf = makeRoughDem(dc.w, dc.d, dc.cellX, dc.cellZ, dc.relief, ++seed);
        const HeightfieldTracer tracer(hf, {skirt, kernel});
        EXPECT_EQ(tracer.kernel(), kernel);
        const Stats r = randomRays(tracer, dc, ++seed);
        const Stats g = specialRays(tracer, ++seed);
        std::cout << "[ skirt " << (skirt ? "on " : "off") << " ] " << dc.name << ": random " << r
                  << "\n                     special " << g << "\n";
        total.add(r);
        special.add(g);
    }
    std::cout << "[ skirt " << (skirt ? "on " : "off") << " ] TOTAL random " << total
              << "\n                 TOTAL special " << special << "\n";
    EXPECT_EQ(total.rays, 100000);
    EXPECT_EQ(total.disagreements(), 0);
    EXPECT_EQ(special.disagreements(), 0);
    EXPECT_GT(total.hits, total.rays / 10);
    EXPECT_GT(special.hits, special.rays / 5);
    if (skirt) {
        EXPECT_GT(total.hits, total.rays * 2 / 5);  // every downward ray must hit
    }
}

TEST(HeightfieldTracer, MatchesBruteForceWithSkirt) {
    for (Kernel k : kernelsHere())
        runComparison(true, 100, k);
}
TEST(HeightfieldTracer, MatchesBruteForceWithoutSkirt) {
    for (Kernel k : kernelsHere())
        runComparison(false, 200, k);
}

// The two kernels on the same 40 000 rays of a rough 601 x 401 grid give the same answers to the
// bit: neither fuses multiply-adds, so a bake is the same bytes on any CPU. (Built with fusing,
// the v3 kernel's t differs on about 3 300 of the long rays.)
TEST(HeightfieldTracer, KernelsAgree) {
    if (!HeightfieldTracer::cpuHasX86_64_v3())
        GTEST_SKIP() << "this CPU has no x86-64-v3: only the baseline kernel runs here";
    const Heightfield hf = makeRoughDem(601, 401, 30.0, 45.0, 2500.0f, 11);
    for (bool skirt : {true, false}) {
        const HeightfieldTracer base(hf, {skirt, Kernel::kBaseline});
        const HeightfieldTracer v3(hf, {skirt, Kernel::kX86_64_v3});
        ASSERT_EQ(base.kernel(), Kernel::kBaseline);
        ASSERT_EQ(v3.kernel(), Kernel::kX86_64_v3);
        std::mt19937 rng(skirt ? 5 : 6);
        std::uniform_real_distribution<float> u01(0.0f, 1.0f);
        int hits = 0, hitMiss = 0, occMiss = 0, tOff = 0, pieceOff = 0;
        for (int i = 0; i < 20000; ++i) {
            const float x = hf.minX() + u01(rng) * (hf.maxX() - hf.minX());
            const float z = hf.minZ() + u01(rng) * (hf.maxZ() - hf.minZ());
            // Half from just above the ground, half from up to 3 km above it and up to a
            // footprint beyond it (long rays over many cells, onto the skirt).
            const bool far = i % 2 == 1;
            const float fx = far ? x + (u01(rng) - 0.5f) * 2.0f * (hf.maxX() - hf.minX()) : x;
            const float fz = far ? z + (u01(rng) - 0.5f) * 2.0f * (hf.maxZ() - hf.minZ()) : z;
            const glm::vec3 o(fx, hf.surfaceHeight(fx, fz) + 0.05f +
                                      (far ? 3000.0f * u01(rng) : 50.0f * u01(rng) * u01(rng)), fz);
            const glm::vec3 d = randomDir(rng);
            RayHit a, b;
            const bool ha = base.intersect(o, d, kInf, a), hb = v3.intersect(o, d, kInf, b);
            hits += ha;
            hitMiss += ha != hb;
            occMiss += base.occluded(o, d, kInf) != v3.occluded(o, d, kInf);
            if (ha && hb) {
                tOff += a.t != b.t || a.position != b.position;
                pieceOff += a.normal != b.normal || a.onTerrain != b.onTerrain;
            }
        }
        std::cout << "[ skirt " << (skirt ? "on " : "off") << " ] 20000 rays, " << hits
                  << " hits; kernels differ: hit/miss " << hitMiss << ", occluded " << occMiss
                  << ", t or position " << tOff << ", normal or piece " << pieceOff << "\n";
        EXPECT_GT(hits, 5000);
        EXPECT_EQ(hitMiss, 0);
        EXPECT_EQ(occMiss, 0);
        EXPECT_EQ(tOff, 0);
        EXPECT_EQ(pieceOff, 0);
    }
}

// The batch API gives each ray exactly what the single-ray calls give (so it is as exact as
// they are against the brute force): for both kernels, with and without the skirt, batches
// shorter than its look-ahead and long ones, finite and infinite tMax, and rays that end before
// they start (NaN, tMax 0, behind the origin).
TEST(HeightfieldTracer, BatchesAgreeWithSingleRays) {
    const Heightfield hf = makeRoughDem(301, 257, 30.0, 45.0, 2500.0f, 21);
    for (Kernel kernel : kernelsHere())
        for (bool skirt : {true, false}) {
            const HeightfieldTracer tracer(hf, {skirt, kernel});
            std::mt19937 rng(skirt ? 31 : 32);
            std::uniform_real_distribution<float> u01(0.0f, 1.0f);
            std::vector<TraceRay> rays;
            for (int i = 0; i < 6000; ++i) {
                const float x = hf.minX() + (1.4f * u01(rng) - 0.2f) * (hf.maxX() - hf.minX());
                const float z = hf.minZ() + (1.4f * u01(rng) - 0.2f) * (hf.maxZ() - hf.minZ());
                const glm::vec3 o(x, hf.surfaceHeight(x, z) + std::pow(10.0f, -2.0f + 5.0f * u01(rng)), z);
                // Runs of rays from one origin (as a probe traces) between incoherent ones.
                const int run = i % 7 == 0 ? 16 : 1;
                for (int k = 0; k < run; ++k)
                    rays.push_back({o, randomDir(rng), i % 3 == 0 ? 3000.0f * u01(rng) : kInf});
            }
            const glm::vec3 up(0.0f, 1.0f, 0.0f), down(0.0f, -1.0f, 0.0f), o(0.0f, hf.maxHeight() + 10.0f, 0.0f);
            rays.push_back({glm::vec3(std::nanf(""), 0.0f, 0.0f), down, kInf});
            rays.push_back({o, down, 0.0f});
            rays.push_back({o, down, -5.0f});
            rays.push_back({o, up, kInf});
            std::shuffle(rays.end() - 4, rays.end(), rng);
            for (size_t n : {size_t(1), size_t(3), rays.size()}) {
                const std::span<const TraceRay> batch(rays.data() + rays.size() - n, n);
                std::vector<RayHit> hits(n);
                std::vector<uint8_t> found(n, 7), blocked(n, 7);
                tracer.intersect(batch, hits, found);
                tracer.occluded(batch, blocked);
                int differ = 0, hitCount = 0;
                for (size_t i = 0; i < n; ++i) {
                    RayHit single;
                    const bool h = tracer.intersect(batch[i].origin, batch[i].dir, batch[i].tMax, single);
                    hitCount += h;
                    differ += found[i] != uint8_t(h) ||
                              blocked[i] != uint8_t(tracer.occluded(batch[i].origin, batch[i].dir, batch[i].tMax));
                    if (h && found[i])
                        differ += hits[i].t != single.t || hits[i].position != single.position ||
                                  hits[i].normal != single.normal || hits[i].onTerrain != single.onTerrain;
                }
                EXPECT_EQ(differ, 0) << kernelName(kernel) << (skirt ? " skirt" : " no skirt") << ", batch of " << n;
                if (n > 1000) {
                    EXPECT_GT(hitCount, int(n) / 5);
                }
            }
            std::vector<RayHit> tooFew(2);
            std::vector<uint8_t> flags(rays.size());
            EXPECT_THROW(tracer.intersect(rays, tooFew, flags), std::invalid_argument);
        }
}

// A tile traces its own window at full resolution and the terrain around it from a coarser grid
// (Options::beyond). Where that grid is the whole grid the window was cut from, every ray, from
// inside the window or outside it, single or batched, meets what a tracer of the whole grid meets.
TEST(HeightfieldTracer, AWindowTracesTheTerrainBeyondItInTheGridAroundIt) {
    const Heightfield whole = makeRoughDem(161, 133, 20.0, 25.0, 900.0f, 41);
    const Heightfield window = whole.window(50, 40, 45, 38);
    const HeightfieldTracer reference(whole);
    const HeightfieldTracer around(whole);
    EXPECT_THROW(HeightfieldTracer(window, {true, Kernel::kAuto, &around}), std::invalid_argument);
    const HeightfieldTracer alone(window, {false});
    for (Kernel kernel : kernelsHere()) {
        const HeightfieldTracer tile(window, {false, kernel, &around});
        std::mt19937 rng(43);
        std::uniform_real_distribution<float> u01(0.0f, 1.0f);
        std::vector<TraceRay> rays;
        for (int i = 0; i < 4000; ++i) {
            // Two in three from over the window (a tile's probes), the rest from anywhere.
            const Heightfield& over = i % 3 ? window : whole;
            const float x = over.minX() + u01(rng) * (over.maxX() - over.minX());
            const float z = over.minZ() + u01(rng) * (over.maxZ() - over.minZ());
            const glm::vec3 o(x, whole.surfaceHeight(x, z) + std::pow(10.0f, 5.0f * u01(rng) - 1.0f), z);
            rays.push_back({o, randomDir(rng), i % 4 == 0 ? 4000.0f * u01(rng) : kInf});
        }
        std::vector<RayHit> hits(rays.size());
        std::vector<uint8_t> found(rays.size()), blocked(rays.size());
        tile.intersect(rays, hits, found);
        tile.occluded(rays, blocked);
        int hitMiss = 0, tOff = 0, batchDiffers = 0, beyondHits = 0, escapeAlone = 0, hitCount = 0;
        for (size_t i = 0; i < rays.size(); ++i) {
            const TraceRay& r = rays[i];
            RayHit a, b, c;
            const bool ha = tile.intersect(r.origin, r.dir, r.tMax, a);
            const bool hb = reference.intersect(r.origin, r.dir, r.tMax, b);
            hitCount += hb;
            hitMiss += ha != hb;
            if (ha && hb && !tAgrees(a.t, b.t)) ++tOff;
            batchDiffers += found[i] != uint8_t(ha) || blocked[i] != uint8_t(tile.occluded(r.origin, r.dir, r.tMax)) ||
                            (ha && (hits[i].t != a.t || hits[i].onTerrain != a.onTerrain));
            if (ha && !a.onTerrain) {
                ++beyondHits;
                // The grid around it answers outside the window only.
                EXPECT_FALSE(a.position.x > window.minX() + 1.0f && a.position.x < window.maxX() - 1.0f &&
                             a.position.z > window.minZ() + 1.0f && a.position.z < window.maxZ() - 1.0f);
            }
            escapeAlone += hb && !alone.intersect(r.origin, r.dir, r.tMax, c);
        }
        EXPECT_EQ(hitMiss, 0) << kernelName(kernel);
        EXPECT_EQ(tOff, 0) << kernelName(kernel);
        EXPECT_EQ(batchDiffers, 0) << kernelName(kernel);
        // The rays exercise both sides: hits beyond the window that the window alone would miss.
        EXPECT_GT(hitCount, 1000);
        EXPECT_GT(beyondHits, 200);
        EXPECT_GT(escapeAlone, 200);
        EXPECT_TRUE(tile.reaches(whole.maxX(), whole.maxZ() + 1e6f));
        EXPECT_FALSE(alone.reaches(whole.maxX(), whole.maxZ()));
    }
}

// Where the grid around a window stands above (or below) the window's own surface at the seam, a
// ray goes on over it at the height above the ground it had when it left the window: a level window
// at 0 m inside a level grid at 3 m, a ray leaving the window 1 m up and descending meets the ground
// where it would have met the window's plane continued, and a rising one escapes.
TEST(HeightfieldTracer, ARayLeavingAWindowKeepsItsHeightOverTheGroundAroundIt) {
    const Heightfield aroundHf(41, 41, 50.0, 50.0, std::vector<float>(41 * 41, 3.0f));
    const Heightfield inner(21, 21, 10.0, 10.0, std::vector<float>(21 * 21, 0.0f));
    const HeightfieldTracer around(aroundHf);
    const HeightfieldTracer tile(inner, {false, Kernel::kAuto, &around});
    // 10 m inside the window's east edge (x = 100 m), on it (a probe on a region's border), and
    // 1.5 cm past it (a cache point there, lifted off the ground along its normal).
    const glm::vec3 origins[] = {{90.0f, 1.0f, 20.0f}, {100.0f, 1.0f, 20.0f}, {100.015f, 1.0f, 20.0f}};
    for (const glm::vec3 o : origins) {
        // Straight down and straight up: no crossing of the window ahead, yet the ray starts over it.
        RayHit hit;
        ASSERT_TRUE(tile.intersect(o, glm::vec3(0.0f, -1.0f, 0.0f), kInf, hit));
        EXPECT_NEAR(hit.t, 1.0f, 1e-3f);
        EXPECT_FALSE(tile.occluded(o, glm::vec3(0.0f, 1.0f, 0.0f), kInf));
        // Nearly parallel to the edge: the window is left only past FLT_MAX.
        EXPECT_FALSE(tile.intersect(o, glm::vec3(0.0f, 1.0f, 1e-36f), kInf, hit));
        EXPECT_FALSE(tile.intersect(o, glm::vec3(1.0f, 0.0f, 0.0f), std::nanf(""), hit));
        for (const float slope : {0.002f, 0.01f, 0.05f}) {
            const glm::vec3 down = glm::normalize(glm::vec3(1.0f, -slope, 0.0f));
            ASSERT_TRUE(tile.intersect(o, down, kInf, hit)) << slope;
            // Beyond the window: 1 m of descent at that slope.
            EXPECT_NEAR(hit.t, 1.0f / -down.y, 1e-3f * hit.t) << slope;
            EXPECT_NEAR(hit.position.y, 0.0f, 1e-3f) << slope;
            EXPECT_FALSE(hit.onTerrain);
            EXPECT_TRUE(tile.occluded(o, down, kInf));
            const glm::vec3 up = glm::normalize(glm::vec3(1.0f, slope, 0.0f));
            EXPECT_FALSE(tile.intersect(o, up, kInf, hit)) << slope;
            EXPECT_FALSE(tile.occluded(o, up, kInf)) << slope;
        }
    }
}

// kAuto resolves to a real kernel: the CPU's best unless TERRALUX_TRACER_KERNEL pins the
// baseline; asking for x86-64-v3 where the CPU lacks it gives the baseline.
TEST(HeightfieldTracer, KernelChoice) {
    const Heightfield hf = makeRoughDem(9, 9, 10.0, 10.0, 50.0f, 3);
    const HeightfieldTracer automatic(hf);
    const char* pin = std::getenv("TERRALUX_TRACER_KERNEL");
    const bool pinned = pin && std::string(pin) == "baseline";
    const Kernel expected = HeightfieldTracer::cpuHasX86_64_v3() && !pinned ? Kernel::kX86_64_v3
                                                                            : Kernel::kBaseline;
    EXPECT_EQ(automatic.kernel(), expected);
    EXPECT_STREQ(HeightfieldTracer::autoKernelName(), kernelName(expected));
    const HeightfieldTracer asked(hf, {true, Kernel::kX86_64_v3});
    EXPECT_EQ(asked.kernel(), HeightfieldTracer::cpuHasX86_64_v3() ? Kernel::kX86_64_v3
                                                                    : Kernel::kBaseline);
}

// Larger non-power-of-two grid: 1000 rays per skirt setting against the reference.
TEST(HeightfieldTracer, MatchesBruteForceOnLargeOddGrid) {
    const Heightfield hf = makeRoughDem(203, 131, 30.0, 45.0, 1500.0f, 7);
    for (Kernel k : kernelsHere())
    for (bool skirt : {true, false}) {
        const HeightfieldTracer tracer(hf, {skirt, k});
        const DemCase dc{"203x131", 203, 131, 30.0, 45.0, 1500.0f, 1000};
        const Stats s = randomRays(tracer, dc, 8);
        std::cout << "[ " << kernelName(k) << ", skirt " << (skirt ? "on " : "off")
                  << " ] 203x131: " << s << "\n";
        EXPECT_EQ(s.disagreements(), 0);
        EXPECT_GT(s.hits, 200);
    }
}

Heightfield flatDem(int w, int d, double cell, float h) {
    return Heightfield(w, d, cell, cell, std::vector<float>(size_t(w) * size_t(d), h));
}

TEST(HeightfieldTracer, FlatPlaneAnalytic) {
    const float h0 = 100.0f;
    const Heightfield hf = flatDem(21, 21, 10.0, h0);  // footprint [-100, 100]^2
    const HeightfieldTracer withSkirt(hf, {true}), noSkirt(hf, {false});
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    int inside = 0, outside = 0;
    for (int i = 0; i < 2000; ++i) {
        const glm::vec3 o(90.0f * u(rng), h0 + 1.0f + 60.0f * (u(rng) + 1.0f), 90.0f * u(rng));
        glm::vec3 dir = randomDir(rng);
        dir.y = -std::fabs(dir.y);
        if (dir.y > -1e-3f)
            continue;
        const double t = (double(h0) - o.y) / dir.y;
        const glm::dvec3 p = glm::dvec3(o) + t * glm::dvec3(dir);
        const bool in = std::fabs(p.x) <= 100.0 && std::fabs(p.z) <= 100.0;
        const bool onSeam =
            std::fabs(std::fabs(p.x) - 100.0) < 1e-3 || std::fabs(std::fabs(p.z) - 100.0) < 1e-3;
        RayHit hit;
        ASSERT_TRUE(withSkirt.intersect(o, dir, kInf, hit));
        EXPECT_NEAR(hit.t, t, 1e-4 * t + 1e-4);
        EXPECT_NEAR(hit.position.x, p.x, 1e-3 * (1 + std::fabs(p.x) * 1e-3));
        EXPECT_NEAR(hit.position.y, h0, 1e-3);
        EXPECT_NEAR(hit.position.z, p.z, 1e-3 * (1 + std::fabs(p.z) * 1e-3));
        EXPECT_FLOAT_EQ(hit.normal.y, 1.0f);
        if (!onSeam) {
            EXPECT_EQ(hit.onTerrain, in);
        }
        EXPECT_TRUE(withSkirt.occluded(o, dir, kInf));
        if (!onSeam) {
            EXPECT_EQ(noSkirt.intersect(o, dir, kInf, hit), in);
            EXPECT_EQ(noSkirt.occluded(o, dir, kInf), in);
        }
        (in ? inside : outside)++;
        // Upward and level rays above the plane escape.
        glm::vec3 up = dir;
        up.y = -up.y;
        EXPECT_FALSE(withSkirt.intersect(o, up, kInf, hit));
        EXPECT_FALSE(withSkirt.occluded(o, glm::normalize(glm::vec3(dir.x, 0.0f, dir.z)), kInf));
        // Leaving the plane from 1 cm above it: no self-hit.
        const glm::vec3 s(o.x, h0 + 0.01f, o.z);
        EXPECT_FALSE(withSkirt.intersect(s, up, kInf, hit));
        EXPECT_FALSE(noSkirt.occluded(s, up, kInf));
    }
    EXPECT_GT(inside, 100);
    EXPECT_GT(outside, 100);
    // Very far, grazing: the skirt is infinite.
    RayHit hit;
    const glm::vec3 graze = glm::normalize(glm::vec3(1.0f, -1e-4f, 0.3f));
    ASSERT_TRUE(withSkirt.intersect({0.0f, h0 + 50.0f, 0.0f}, graze, kInf, hit));
    EXPECT_NEAR(hit.t, 50.0 / 1e-4 * glm::length(glm::vec3(1.0f, 1e-4f, 0.3f)), 5.0);
    EXPECT_FALSE(hit.onTerrain);
    EXPECT_FALSE(noSkirt.intersect({0.0f, h0 + 50.0f, 0.0f}, graze, kInf, hit));
    // Vertical ray straight down onto a vertex and onto the border.
    ASSERT_TRUE(noSkirt.intersect({10.0f, h0 + 5.0f, -20.0f}, {0, -1, 0}, kInf, hit));
    EXPECT_NEAR(hit.t, 5.0f, 1e-5f);
    ASSERT_TRUE(noSkirt.intersect({100.0f, h0 + 5.0f, 100.0f}, {0, -1, 0}, kInf, hit));
    EXPECT_NEAR(hit.t, 5.0f, 1e-5f);
    // tMax short of the plane.
    EXPECT_FALSE(withSkirt.intersect({0.0f, h0 + 5.0f, 0.0f}, {0, -1, 0}, 4.9f, hit));
    EXPECT_TRUE(withSkirt.occluded({0.0f, h0 + 5.0f, 0.0f}, {0, -1, 0}, 5.1f));
}

// A plane tilted in x and z: the skirt strips continue the border profile level outward, so a
// ray leaving through the west edge hits h(minX, z), not the continued plane.
TEST(HeightfieldTracer, TiltedPlaneSkirtAnalytic) {
    const int n = 11;
    const double cell = 10.0;  // footprint [-50, 50]^2
    const double a = 0.3, b = -0.2;
    std::vector<float> h(n * n);
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c)
            h[r * n + c] = float(a * (c - 5) * cell + b * (r - 5) * cell);
    const Heightfield hf(n, n, cell, cell, h);
    const HeightfieldTracer tracer(hf, {true});
    // West strip: y = a * -50 + b * z; ray from (-40, 20, 10) heading west and down.
    const glm::dvec3 o(-40.0, 20.0, 10.0), dir = glm::normalize(glm::dvec3(-1.0, -0.25, 0.1));
    // o.y + t dir.y = a * -50 + b * (o.z + t dir.z)
    const double t = (a * -50.0 + b * o.z - o.y) / (dir.y - b * dir.z);
    const glm::dvec3 p = o + t * dir;
    ASSERT_LT(p.x, -50.0);
    ASSERT_GT(p.z, -50.0);
    ASSERT_LT(p.z, 50.0);
    RayHit hit;
    ASSERT_TRUE(tracer.intersect(glm::vec3(o), glm::vec3(dir), kInf, hit));
    EXPECT_NEAR(hit.t, t, 1e-4);
    EXPECT_FALSE(hit.onTerrain);
    const glm::dvec3 nStrip = glm::normalize(glm::dvec3(0.0, 1.0, -b));
    EXPECT_NEAR(hit.normal.x, nStrip.x, 1e-6);
    EXPECT_NEAR(hit.normal.y, nStrip.y, 1e-6);
    EXPECT_NEAR(hit.normal.z, nStrip.z, 1e-6);
    // North-east corner quadrant: level at the corner height h(50, -50).
    const double hc = a * 50.0 + b * -50.0;
    const glm::dvec3 o2(45.0, hc + 30.0, -45.0), dir2 = glm::normalize(glm::dvec3(1.0, -0.5, -1.0));
    const double t2 = (hc - o2.y) / dir2.y;
    ASSERT_TRUE(tracer.intersect(glm::vec3(o2), glm::vec3(dir2), kInf, hit));
    EXPECT_NEAR(hit.t, t2, 1e-4);
    EXPECT_FALSE(hit.onTerrain);
    EXPECT_FLOAT_EQ(hit.normal.y, 1.0f);
    // Inside: the plane's own normal.
    ASSERT_TRUE(tracer.intersect({3.0f, 100.0f, 7.0f}, {0, -1, 0}, kInf, hit));
    EXPECT_NEAR(hit.position.y, a * 3.0 + b * 7.0, 1e-4);
    const glm::dvec3 nPlane = glm::normalize(glm::dvec3(-a, 1.0, -b));
    EXPECT_NEAR(hit.normal.x, nPlane.x, 1e-6);
    EXPECT_NEAR(hit.normal.z, nPlane.z, 1e-6);
    EXPECT_TRUE(hit.onTerrain);
}

TEST(HeightfieldTracer, SinglePeak) {
    const int n = 41;
    const double cell = 25.0;  // footprint [-500, 500]^2
    std::vector<float> h(n * n, 0.0f);
    h[20 * n + 20] = 800.0f;  // a one-vertex spike at the centre
    const Heightfield hf(n, n, cell, cell, h);
    for (bool skirt : {true, false}) {
        const HeightfieldTracer tracer(hf, {skirt});
        RayHit hit;
        // Level ray from 5 km west at 400 m, straight at the spike: it hits the west face of the
        // spike, where the faces fall from 800 m to 0 over one cell.
        const glm::vec3 o(-5000.0f, 400.0f, 0.0f);
        ASSERT_TRUE(tracer.intersect(o, {1, 0, 0}, kInf, hit));
        EXPECT_NEAR(hit.position.x, -12.5f, 1e-3f);
        EXPECT_NEAR(hit.t, 5000.0f - 12.5f, 1e-3f);
        EXPECT_TRUE(hit.onTerrain);
        EXPECT_LT(hit.normal.x, 0.0f);
        // Aimed from afar at the tip region from above.
        const glm::vec3 o2(-3000.0f, 2000.0f, 1000.0f);
        const glm::vec3 d2 = glm::normalize(glm::vec3(0.0f, 790.0f, 0.0f) - o2);
        ASSERT_TRUE(tracer.intersect(o2, d2, kInf, hit));
        EXPECT_GT(hit.position.y, 700.0f);
        EXPECT_TRUE(hit.onTerrain);
        // Passing 1 m above the tip: escapes (the level ray never meets the level skirt).
        EXPECT_FALSE(tracer.intersect({-5000.0f, 801.0f, 0.0f}, {1, 0, 0}, kInf, hit));
        EXPECT_FALSE(tracer.occluded({-5000.0f, 801.0f, 0.0f}, {1, 0, 0}, kInf));
        // Descending slightly, clearing the tip by about 1 m: lands far beyond it (skirt) or
        // escapes (no skirt).
        const glm::vec3 d3 = glm::normalize(glm::vec3(1.0f, -0.01f, 0.0f));
        const glm::vec3 o3(-5000.0f, 801.0f + 0.01f * 5000.0f, 0.0f);
        const bool h3 = tracer.intersect(o3, d3, kInf, hit);
        EXPECT_EQ(h3, skirt);
        if (h3) {
            EXPECT_NEAR(hit.position.x, 80100.0f, 10.0f);
            EXPECT_FALSE(hit.onTerrain);
        }
        // Passing 1 m below the tip hits it.
        EXPECT_TRUE(tracer.occluded({-5000.0f, 799.0f, 0.0f}, {1, 0, 0}, kInf));
    }
}

TEST(HeightfieldTracer, DegenerateGrids) {
    RayHit hit;
    // 1x1: the skirt plane at that height, or nothing.
    const Heightfield one(1, 1, 30.0, 45.0, {12.0f});
    const HeightfieldTracer on(one, {true}), off(one, {false});
    for (glm::vec3 o : {glm::vec3(0, 20, 0), glm::vec3(1000, 20, -700), glm::vec3(-3, 13, 5)}) {
        const glm::vec3 dir = glm::normalize(glm::vec3(0.3f, -1.0f, -0.2f));
        ASSERT_TRUE(on.intersect(o, dir, kInf, hit));
        EXPECT_NEAR(hit.t, (12.0f - o.y) / dir.y, 1e-4f);
        EXPECT_NEAR(hit.position.y, 12.0f, 1e-4f);
        EXPECT_FALSE(hit.onTerrain);
        EXPECT_FALSE(off.intersect(o, dir, kInf, hit));
        EXPECT_FALSE(off.occluded(o, dir, kInf));
        EXPECT_FALSE(on.intersect(o, -dir, kInf, hit));
    }
    // 1xN: the profile along z extruded along x.
    const Heightfield col(1, 3, 30.0, 45.0, {0.0f, 90.0f, 0.0f});  // z = -45, 0, 45
    const HeightfieldTracer colOn(col, {true}), colOff(col, {false});
    ASSERT_TRUE(colOn.intersect({500.0f, 200.0f, 22.5f}, {0, -1, 0}, kInf, hit));
    EXPECT_NEAR(hit.position.y, 45.0f, 1e-4f);
    EXPECT_NEAR(hit.normal.z, glm::normalize(glm::vec3(0, 1, 2)).z, 1e-6f);
    EXPECT_FALSE(colOff.intersect({0.0f, 200.0f, 22.5f}, {0, -1, 0}, kInf, hit));
    // Nx1: the profile along x extruded along z.
    const Heightfield rowHf(3, 1, 30.0, 45.0, {0.0f, 60.0f, 0.0f});  // x = -30, 0, 30
    const HeightfieldTracer rowOn(rowHf, {true});
    ASSERT_TRUE(rowOn.intersect({-15.0f, 200.0f, -9000.0f}, {0, -1, 0}, kInf, hit));
    EXPECT_NEAR(hit.position.y, 30.0f, 1e-4f);
    EXPECT_FALSE(hit.onTerrain);
}

// The baseline marcher samples the same surface: on smooth terrain it agrees with the tracer
// except for the odd ray grazing a crest between two samples.
TEST(HeightfieldTracer, RayMarchBaselineAgreesOnSmoothTerrain) {
    std::vector<float> h(65 * 65);
    for (int r = 0; r < 65; ++r)
        for (int c = 0; c < 65; ++c)
            h[size_t(r) * 65 + size_t(c)] =
                float(200.0 * std::sin(c * 0.1) * std::cos(r * 0.07) + 1.5 * r);
    const Heightfield hf(65, 65, 30.0, 45.0, std::move(h));
    const HeightfieldTracer tracer(hf);
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    int rays = 0, agree = 0;
    for (int i = 0; i < 3000; ++i) {
        const float x = hf.minX() + u01(rng) * (hf.maxX() - hf.minX());
        const float z = hf.minZ() + u01(rng) * (hf.maxZ() - hf.minZ());
        const glm::vec3 o(x, hf.surfaceHeight(x, z) + 2.0f, z), dir = randomDir(rng);
        RayHit a, b;
        const bool ha = tracer.intersect(o, dir, kInf, a);
        const bool hb = intersectRayMarch(hf, o, dir, kInf, b);
        ++rays;
        agree += ha == hb && (!ha || std::fabs(a.t - b.t) <= 0.01f + 1e-4f * a.t);
    }
    std::cout << "[ marcher ] " << agree << " of " << rays << " rays agree with the tracer\n";
    EXPECT_GE(agree, rays * 99 / 100);
    // Flat ground: analytic.
    const Heightfield flat(5, 5, 10.0, 10.0, std::vector<float>(25, 3.0f));
    RayHit hit;
    const glm::vec3 dir = glm::normalize(glm::vec3(1.0f, -0.5f, 0.2f));
    ASSERT_TRUE(intersectRayMarch(flat, {0.0f, 23.0f, 0.0f}, dir, kInf, hit));  // lands at x = 40
    EXPECT_NEAR(hit.t, 20.0f / 0.5f * glm::length(glm::vec3(1.0f, -0.5f, 0.2f)), 1e-3f);
    EXPECT_FALSE(hit.onTerrain);
    EXPECT_FALSE(intersectRayMarch(flat, {0.0f, 23.0f, 0.0f}, -dir, kInf, hit));
}

TEST(HeightfieldTracer, RejectsBadInput) {
    const Heightfield hf = makeRoughDem(9, 9, 10.0, 10.0, 50.0f, 1);
    const HeightfieldTracer tracer(hf);
    RayHit hit;
    EXPECT_FALSE(tracer.intersect({0, 100, 0}, {0, -1, 0}, 0.0f, hit));
    EXPECT_FALSE(tracer.intersect({0, 100, 0}, {0, -1, 0}, -5.0f, hit));
    EXPECT_FALSE(tracer.intersect({0, 100, 0}, {0, -1, 0}, std::nanf(""), hit));
    EXPECT_FALSE(tracer.intersect({std::nanf(""), 100, 0}, {0, -1, 0}, kInf, hit));
    EXPECT_FALSE(tracer.occluded({0, 100, 0}, {0, -kInf, 0}, kInf));
    EXPECT_EQ(tracer.levelCount(), 4);  // 8x8 cells -> 4x4 -> 2x2 -> 1x1
}

}  // namespace
}  // namespace terralux
