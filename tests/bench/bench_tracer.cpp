// HeightfieldTracer throughput on a 1201 x 1201 DEM, against the fixed-step ray marcher.
//
// DEM: a raw little-endian float32 grid named by TERRALUX_BENCH_DEM_RAW, with
// TERRALUX_BENCH_DEM_W / _H (samples) and TERRALUX_BENCH_DEM_CX / _CZ (cell size, metres);
// e.g. `gdal_translate -of ENVI -ot Float32 dem.tif dem.raw`. Samples below -1e4 (SRTM voids)
// are filled from their neighbours. Without it, a synthetic fractal 1201 x 1201 DEM with about
// 2 km of relief and 30 m cells. The "dem" context line and each benchmark's label say which.
//
// Rays: incoherent, from random points 2 m above the surface, directions uniform on the full
// sphere, tMax = infinity, skirt on. All numbers are single-threaded.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "DemImport.h"
#include "Membrane.h"
#include "bake/HeightfieldTracer.h"
#include "terrain/Heightfield.h"

namespace terralux {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kRayCount = 1 << 16;
constexpr int kBatch = 1024;  // rays per benchmark iteration

struct BenchDem {
    Heightfield hf;
    std::string source;
};

bool envInt(const char* name, long& out) {
    const char* s = std::getenv(name);
    if (!s || !*s)
        return false;
    char* end = nullptr;
    out = std::strtol(s, &end, 10);
    return end && *end == '\0';
}

bool envDouble(const char* name, double& out) {
    const char* s = std::getenv(name);
    if (!s || !*s)
        return false;
    char* end = nullptr;
    out = std::strtod(s, &end);
    return end && *end == '\0';
}

// Voids (SRTM -32768) filled by repeated averaging of valid 4-neighbours.
void fillVoids(std::vector<float>& h, int w, int d) {
    auto invalid = [](float v) { return !std::isfinite(v) || v < -1e4f; };
    std::vector<uint8_t> bad(h.size());
    size_t left = 0;
    for (size_t i = 0; i < h.size(); ++i)
        left += bad[i] = invalid(h[i]);
    while (left > 0) {
        std::vector<uint8_t> next = bad;
        size_t filled = 0;
        for (int r = 0; r < d; ++r)
            for (int c = 0; c < w; ++c) {
                const size_t i = size_t(r) * size_t(w) + size_t(c);
                if (!bad[i])
                    continue;
                double sum = 0;
                int n = 0;
                auto take = [&](int cc, int rr) {
                    if (cc < 0 || rr < 0 || cc >= w || rr >= d)
                        return;
                    const size_t j = size_t(rr) * size_t(w) + size_t(cc);
                    if (!bad[j]) {
                        sum += h[j];
                        ++n;
                    }
                };
                take(c - 1, r);
                take(c + 1, r);
                take(c, r - 1);
                take(c, r + 1);
                if (n) {
                    h[i] = float(sum / n);
                    next[i] = 0;
                    ++filled;
                }
            }
        if (filled == 0) {  // nothing valid at all
            std::fill(h.begin(), h.end(), 0.0f);
            return;
        }
        bad.swap(next);
        left -= filled;
    }
}

bool loadRawDem(BenchDem& out) {
    const char* path = std::getenv("TERRALUX_BENCH_DEM_RAW");
    if (!path || !*path)
        return false;
    long w = 0, d = 0;
    double cx = 0, cz = 0;
    if (!envInt("TERRALUX_BENCH_DEM_W", w) || !envInt("TERRALUX_BENCH_DEM_H", d) ||
        !envDouble("TERRALUX_BENCH_DEM_CX", cx) || !envDouble("TERRALUX_BENCH_DEM_CZ", cz) ||
        w < 1 || d < 1 || !(cx > 0) || !(cz > 0)) {
        std::fprintf(stderr, "TERRALUX_BENCH_DEM_RAW set but W/H/CX/CZ missing or invalid\n");
        return false;
    }
    std::ifstream in(path, std::ios::binary);
    std::vector<float> h(size_t(w) * size_t(d));
    in.read(reinterpret_cast<char*>(h.data()), std::streamsize(h.size() * sizeof(float)));
    if (!in || in.gcount() != std::streamsize(h.size() * sizeof(float))) {
        std::fprintf(stderr, "cannot read %ld x %ld float32 samples from %s\n", w, d, path);
        return false;
    }
    if constexpr (std::endian::native == std::endian::big) {
        for (float& v : h) {
            const uint32_t b = std::bit_cast<uint32_t>(v);
            v = std::bit_cast<float>((b >> 24) | ((b >> 8) & 0xff00u) | ((b << 8) & 0xff0000u) |
                                     (b << 24));
        }
    }
    size_t voids = 0;
    for (float v : h)
        voids += !std::isfinite(v) || v < -1e4f;
    fillVoids(h, int(w), int(d));
    const std::string file(path);
    char desc[512];
    std::snprintf(desc, sizeof desc, "real DEM %s %ldx%ld, %gx%g m cells, %zu voids filled",
                  file.substr(file.find_last_of('/') + 1).c_str(), w, d, cx, cz, voids);
    out.hf = Heightfield(int(w), int(d), cx, cz, std::move(h));
    out.source = desc;
    return true;
}

// Multi-octave value noise (smoothstep-interpolated lattice, gain 0.5), rescaled to 2 km relief.
BenchDem syntheticDem() {
    const int n = 1201;
    std::mt19937 rng(20240601);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    std::vector<float> h(size_t(n) * size_t(n), 0.0f);
    float amp = 1.0f;
    for (int period = 512; period >= 2; period /= 2, amp *= 0.5f) {
        const int g = n / period + 2;
        std::vector<float> lattice(size_t(g) * size_t(g));
        for (float& v : lattice)
            v = u01(rng);
        auto L = [&](int i, int j) { return lattice[size_t(j) * size_t(g) + size_t(i)]; };
        for (int r = 0; r < n; ++r)
            for (int c = 0; c < n; ++c) {
                const int i = c / period, j = r / period;
                float fx = float(c % period) / float(period),
                      fz = float(r % period) / float(period);
                fx = fx * fx * (3 - 2 * fx);
                fz = fz * fz * (3 - 2 * fz);
                const float a = L(i, j) + fx * (L(i + 1, j) - L(i, j));
                const float b = L(i, j + 1) + fx * (L(i + 1, j + 1) - L(i, j + 1));
                h[size_t(r) * size_t(n) + size_t(c)] += amp * (a + fz * (b - a));
            }
    }
    const auto [lo, hi] = std::minmax_element(h.begin(), h.end());
    const float scale = 2000.0f / (*hi - *lo), base = *lo;
    for (float& v : h)
        v = 300.0f + (v - base) * scale;
    return {Heightfield(n, n, 30.0, 30.0, std::move(h)),
            "synthetic fractal DEM 1201x1201, 30x30 m cells, 2000 m relief"};
}

const BenchDem& dem() {
    static const BenchDem d = [] {
        BenchDem b;
        if (!loadRawDem(b))
            b = syntheticDem();
        std::fprintf(stderr, "bench_tracer DEM: %s (heights %.1f .. %.1f m)\n", b.source.c_str(),
                     b.hf.minHeight(), b.hf.maxHeight());
        return b;
    }();
    return d;
}

const HeightfieldTracer& tracer() {
    static const HeightfieldTracer t(dem().hf, {true});
    return t;
}

struct Rays {
    std::vector<glm::vec3> origin, dir;
};

const Rays& rays() {
    static const Rays r = [] {
        const Heightfield& hf = dem().hf;
        std::mt19937 rng(7);
        std::uniform_real_distribution<float> u01(0.0f, 1.0f);
        std::normal_distribution<float> g;
        Rays out;
        for (int i = 0; i < kRayCount; ++i) {
            const float x = hf.minX() + u01(rng) * (hf.maxX() - hf.minX());
            const float z = hf.minZ() + u01(rng) * (hf.maxZ() - hf.minZ());
            out.origin.emplace_back(x, hf.surfaceHeight(x, z) + 2.0f, z);
            glm::vec3 d;
            do
                d = glm::vec3(g(rng), g(rng), g(rng));
            while (glm::dot(d, d) < 1e-8f);
            out.dir.push_back(glm::normalize(d));
        }
        return out;
    }();
    return r;
}

const struct RegisterContext {
    RegisterContext() { benchmark::AddCustomContext("dem", dem().source); }
} registerContext;

template <class Trace>
void runRays(benchmark::State& state, Trace&& trace) {
    const Rays& r = rays();
    size_t next = 0;
    int64_t hits = 0;
    for (auto _ : state) {
        for (int i = 0; i < kBatch; ++i) {
            const size_t k = next++ & (kRayCount - 1);
            const bool h = trace(r.origin[k], r.dir[k]);
            benchmark::DoNotOptimize(h);
            hits += h;
        }
    }
    const int64_t n = int64_t(state.iterations()) * kBatch;
    state.SetItemsProcessed(n);
    state.counters["hit_fraction"] = double(hits) / double(std::max<int64_t>(n, 1));
    state.SetLabel(dem().source);
}

void BM_Tracer(benchmark::State& state) {
    const HeightfieldTracer& t = tracer();
    RayHit hit;
    runRays(state, [&](const glm::vec3& o, const glm::vec3& d) {
        const bool h = t.intersect(o, d, kInf, hit);
        benchmark::DoNotOptimize(hit);
        return h;
    });
}
BENCHMARK(BM_Tracer)->Unit(benchmark::kMillisecond);

void BM_TracerOccluded(benchmark::State& state) {
    const HeightfieldTracer& t = tracer();
    runRays(state, [&](const glm::vec3& o, const glm::vec3& d) { return t.occluded(o, d, kInf); });
}
BENCHMARK(BM_TracerOccluded)->Unit(benchmark::kMillisecond);

void BM_RayMarch(benchmark::State& state) {
    const Heightfield& hf = dem().hf;
    RayHit hit;
    runRays(state, [&](const glm::vec3& o, const glm::vec3& d) {
        const bool h = intersectRayMarch(hf, o, d, kInf, hit);
        benchmark::DoNotOptimize(hit);
        return h;
    });
}
BENCHMARK(BM_RayMarch)->Unit(benchmark::kMillisecond);

void BM_TracerBuild(benchmark::State& state) {
    for (auto _ : state) {
        HeightfieldTracer t(dem().hf, {true});
        benchmark::DoNotOptimize(t);
    }
    state.SetLabel(dem().source);
}
BENCHMARK(BM_TracerBuild)->Unit(benchmark::kMillisecond);

// One pass over all rays with both methods: what the marcher gets wrong (it can step over thin
// ridges and land farther away, or miss the terrain entirely).
void BM_CompareMarcher(benchmark::State& state) {
    const Heightfield& hf = dem().hf;
    const HeightfieldTracer& t = tracer();
    const Rays& r = rays();
    int64_t both = 0, tracerOnly = 0, marchOnly = 0, fartherHit = 0, tracerHits = 0;
    for (auto _ : state) {
        for (int k = 0; k < kRayCount; ++k) {
            RayHit a, b;
            const bool ha = t.intersect(r.origin[k], r.dir[k], kInf, a);
            const bool hb = intersectRayMarch(hf, r.origin[k], r.dir[k], kInf, b);
            tracerHits += ha;
            if (ha && hb) {
                ++both;
                fartherHit += b.t > a.t + std::max(1.0f, 1e-3f * a.t);
            }
            tracerOnly += ha && !hb;
            marchOnly += hb && !ha;
        }
    }
    state.counters["rays"] = kRayCount;
    state.counters["tracer_hits"] = double(tracerHits);
    state.counters["march_missed"] = double(tracerOnly);
    state.counters["march_extra"] = double(marchOnly);
    state.counters["march_farther_hit"] = double(fartherHit);
    state.SetLabel(dem().source);
}
BENCHMARK(BM_CompareMarcher)->Iterations(1)->Unit(benchmark::kMillisecond);

// A few hundred rays against the brute-force reference (every triangle, ~2.9 M per ray).
void BM_CompareBruteForce(benchmark::State& state) {
    const Heightfield& hf = dem().hf;
    const HeightfieldTracer& t = tracer();
    const Rays& r = rays();
    const int n = int(state.range(0));
    int64_t hits = 0, hitMiss = 0, tMismatch = 0;
    for (auto _ : state) {
        for (int k = 0; k < n; ++k) {
            RayHit a, b;
            const bool ha = t.intersect(r.origin[k], r.dir[k], kInf, a);
            const bool hb = intersectBruteForce(hf, true, r.origin[k], r.dir[k], kInf, b);
            hits += hb;
            hitMiss += ha != hb;
            tMismatch += ha && hb && std::fabs(a.t - b.t) > std::max(1e-3f, 1e-4f * b.t);
        }
    }
    state.counters["rays"] = n;
    state.counters["brute_hits"] = double(hits);
    state.counters["hit_miss_disagree"] = double(hitMiss);
    state.counters["t_disagree"] = double(tMismatch);
    state.SetLabel(dem().source);
}
BENCHMARK(BM_CompareBruteForce)->Arg(256)->Iterations(1)->Unit(benchmark::kMillisecond);

// A smooth field with a round hole of `size` cells across in a grid of 5/3 that side.
struct HoleCase {
    int n = 0;
    std::vector<float> field;
    std::vector<uint8_t> mask;
};
HoleCase roundHole(int size) {
    HoleCase hole;
    const int n = hole.n = size * 5 / 3, c = n / 2, r = size / 2;
    hole.field.resize(size_t(n) * n);
    hole.mask.assign(hole.field.size(), 0);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            hole.field[size_t(y) * n + x] = float(500 + 200 * std::sin(0.02 * x) * std::cos(0.015 * y));
            hole.mask[size_t(y) * n + x] = (x - c) * (x - c) + (y - c) * (y - c) <= r * r;
        }
    return hole;
}

// The void fill of DEM import, by GDAL alone (range(1) == 0) or by GDAL and the membrane (1).
void BM_VoidFillLargeHole(benchmark::State& state) {
    const HoleCase hole = roundHole(int(state.range(0)));
    const VoidFill method = state.range(1) ? VoidFill::GdalMembrane : VoidFill::Gdal;
    for (auto _ : state) {
        std::vector<float> g = hole.field;
        terralux::fillVoids(g, hole.n, hole.n, hole.mask, method);
        benchmark::DoNotOptimize(g.data());
    }
    state.counters["hole_cells"] = double(std::count(hole.mask.begin(), hole.mask.end(), uint8_t(1)));
}
BENCHMARK(BM_VoidFillLargeHole)
    ->ArgsProduct({{300, 1000}, {0, 1}})
    ->ArgNames({"hole", "membrane"})
    ->Iterations(2)
    ->Unit(benchmark::kMillisecond);

// The membrane solve alone on the same holes, from GDAL's fill.
void BM_MembraneSolve(benchmark::State& state) {
    const HoleCase hole = roundHole(int(state.range(0)));
    std::vector<float> start = hole.field;
    terralux::fillVoids(start, hole.n, hole.n, hole.mask, VoidFill::Gdal);
    MembraneReport report;
    for (auto _ : state) {
        std::vector<float> g = start;
        report = terralux::membraneFill(g, hole.n, hole.n, hole.mask);
        benchmark::DoNotOptimize(g.data());
    }
    state.counters["iterations"] = double(report.iterations);
}
BENCHMARK(BM_MembraneSolve)->Arg(300)->Arg(1000)->Arg(2000)->Iterations(2)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace terralux
