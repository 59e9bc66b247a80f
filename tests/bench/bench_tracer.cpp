// HeightfieldTracer throughput on a 1201 x 1201 DEM, against the fixed-step ray marcher.
//
// DEM: a raw little-endian float32 grid named by TERRALUX_BENCH_DEM_RAW, with
// TERRALUX_BENCH_DEM_W / _H (samples) and TERRALUX_BENCH_DEM_CX / _CZ (cell size, metres);
// e.g. `gdal_translate -of ENVI -ot Float32 dem.tif dem.raw`. Samples below -1e4 (SRTM voids)
// are filled from their neighbours. Without it, a synthetic fractal 1201 x 1201 DEM with about
// 2 km of relief and 30 m cells. The "dem" context line and each benchmark's label say which.
//
// Three ray sets of 65 536 rays each, tMax = infinity, traced in order (argument `rays`):
//   0 incoherent: random points 2 m above the surface, directions uniform on the full sphere;
//   1 probe-ordered, as the bake traces a probe grid: 16 x 16 probes 5 m above the surface, 256
//     directions each (a Fibonacci sphere turned by a random rotation per probe), probe by probe;
//   2 cache-ordered, as the irradiance cache traces: 1 024 surface points lifted 5 cm along the
//     normal, 64 cosine-weighted directions about the normal each, point by point.
// BM_TracerBatch* trace the same sets through the batch API, kBatch rays per call.
// The tracer runs with the skirt on, except in the Embree comparison (built when libembree-dev is
// installed), where both sides trace the same triangles (same heights, same diagonal) without a
// skirt. All numbers are single-threaded.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <span>
#include <random>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#ifdef TERRALUX_HAVE_EMBREE
#include <embree3/rtcore.h>
#endif

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

using Kernel = HeightfieldTracer::Kernel;

// kernel: 0 baseline, 1 x86-64-v3 (the benchmark is skipped where the CPU lacks it), 2 the
// process default (what a bake uses).
const HeightfieldTracer& tracer(int kernel = 2, bool skirt = true) {
    static const HeightfieldTracer t[2][3] = {
        {HeightfieldTracer(dem().hf, {false, Kernel::kBaseline}),
         HeightfieldTracer(dem().hf, {false, Kernel::kX86_64_v3}),
         HeightfieldTracer(dem().hf, {false, Kernel::kAuto})},
        {HeightfieldTracer(dem().hf, {true, Kernel::kBaseline}),
         HeightfieldTracer(dem().hf, {true, Kernel::kX86_64_v3}),
         HeightfieldTracer(dem().hf, {true, Kernel::kAuto})}};
    return t[skirt][kernel];
}

const HeightfieldTracer& tracerNoSkirt(int kernel = 2) { return tracer(kernel, false); }

const char* const kKernelNames[] = {"baseline kernel", "x86-64-v3 kernel", "default kernel"};

// Skips (and says why) a kernel this CPU cannot run.
bool kernelRuns(benchmark::State& state, int kernel) {
    if (kernel == 1 && !HeightfieldTracer::cpuHasX86_64_v3()) {
        state.SkipWithError("this CPU has no x86-64-v3");
        return false;
    }
    return true;
}

struct Rays {
    std::vector<glm::vec3> origin, dir;
};

enum RaySet : int { kIncoherent = 0, kProbeOrdered = 1, kCacheOrdered = 2 };
const char* const kRaySetNames[] = {"incoherent", "probe-ordered", "cache-ordered"};

glm::vec3 uniformSphere(std::mt19937& rng) {
    std::normal_distribution<float> g;
    glm::vec3 d;
    do
        d = glm::vec3(g(rng), g(rng), g(rng));
    while (glm::dot(d, d) < 1e-8f);
    return glm::normalize(d);
}

Rays incoherentRays() {
    const Heightfield& hf = dem().hf;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    Rays out;
    for (int i = 0; i < kRayCount; ++i) {
        const float x = hf.minX() + u01(rng) * (hf.maxX() - hf.minX());
        const float z = hf.minZ() + u01(rng) * (hf.maxZ() - hf.minZ());
        out.origin.emplace_back(x, hf.surfaceHeight(x, z) + 2.0f, z);
        out.dir.push_back(uniformSphere(rng));
    }
    return out;
}

Rays probeOrderedRays() {
    const Heightfield& hf = dem().hf;
    constexpr int kProbes = 16, kDirections = kRayCount / (kProbes * kProbes);
    constexpr double kGolden = 2.399963229728653;  // pi (3 - sqrt 5)
    std::mt19937 rng(11);
    Rays out;
    for (int j = 0; j < kProbes; ++j)
        for (int i = 0; i < kProbes; ++i) {
            const float x = hf.minX() + (float(i) + 0.5f) / kProbes * (hf.maxX() - hf.minX());
            const float z = hf.minZ() + (float(j) + 0.5f) / kProbes * (hf.maxZ() - hf.minZ());
            const glm::vec3 origin(x, hf.surfaceHeight(x, z) + 5.0f, z);
            const glm::vec3 axis = uniformSphere(rng);
            const float angle = std::uniform_real_distribution<float>(0.0f, 6.2831853f)(rng);
            const glm::quat turn = glm::angleAxis(angle, axis);
            for (int k = 0; k < kDirections; ++k) {
                const double y = 1.0 - (k + 0.5) * 2.0 / kDirections, r = std::sqrt(1.0 - y * y);
                const glm::vec3 d(float(r * std::cos(kGolden * k)), float(y), float(r * std::sin(kGolden * k)));
                out.origin.push_back(origin);
                out.dir.push_back(glm::normalize(turn * d));
            }
        }
    return out;
}

Rays cacheOrderedRays() {
    const Heightfield& hf = dem().hf;
    constexpr int kPoints = 1024, kDirections = kRayCount / kPoints;
    std::mt19937 rng(13);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    Rays out;
    for (int p = 0; p < kPoints; ++p) {
        const float x = hf.minX() + u01(rng) * (hf.maxX() - hf.minX());
        const float z = hf.minZ() + u01(rng) * (hf.maxZ() - hf.minZ());
        const glm::vec3 n = hf.surfaceNormal(x, z);
        const glm::vec3 origin = glm::vec3(x, hf.surfaceHeight(x, z), z) + 0.05f * n;
        // A frame about the normal; cosine-weighted directions (Malley's method).
        const glm::vec3 t = glm::normalize(std::fabs(n.x) < 0.9f ? glm::cross(n, glm::vec3(1, 0, 0))
                                                                 : glm::cross(n, glm::vec3(0, 0, 1)));
        const glm::vec3 b = glm::cross(n, t);
        for (int k = 0; k < kDirections; ++k) {
            const float r = std::sqrt(u01(rng)), phi = 6.2831853f * u01(rng);
            const float a = r * std::cos(phi), c = r * std::sin(phi);
            out.origin.push_back(origin);
            out.dir.push_back(glm::normalize(a * t + c * b + std::sqrt(std::max(0.0f, 1.0f - r * r)) * n));
        }
    }
    return out;
}

const Rays& rays(int set = kIncoherent) {
    static const Rays sets[] = {incoherentRays(), probeOrderedRays(), cacheOrderedRays()};
    return sets[set];
}

const struct RegisterContext {
    RegisterContext() { benchmark::AddCustomContext("dem", dem().source); }
} registerContext;

template <class Trace>
void runRays(benchmark::State& state, int set, Trace&& trace, const char* kernel = kKernelNames[2]) {
    const Rays& r = rays(set);
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
    state.SetLabel(std::string(kRaySetNames[set]) + "; " + kernel + "; " + dem().source);
}

// One of the tracer's benchmarks: arguments the ray set and the kernel (0 baseline, 1 x86-64-v3).
void traceRays(benchmark::State& state, bool skirt, bool anyHit) {
    const int kernel = int(state.range(1));
    if (!kernelRuns(state, kernel))
        return;
    const HeightfieldTracer& t = tracer(kernel, skirt);
    RayHit hit;
    runRays(state, int(state.range(0)), [&](const glm::vec3& o, const glm::vec3& d) {
        if (anyHit)
            return t.occluded(o, d, kInf);
        const bool h = t.intersect(o, d, kInf, hit);
        benchmark::DoNotOptimize(hit);
        return h;
    }, kKernelNames[kernel]);
}

void BM_Tracer(benchmark::State& state) { traceRays(state, true, false); }
BENCHMARK(BM_Tracer)->ArgNames({"rays", "kernel"})->ArgsProduct({{0, 1, 2}, {0, 1}})->Unit(benchmark::kMillisecond);

void BM_TracerOccluded(benchmark::State& state) { traceRays(state, true, true); }
BENCHMARK(BM_TracerOccluded)->ArgNames({"rays", "kernel"})->ArgsProduct({{0, 1, 2}, {0, 1}})->Unit(benchmark::kMillisecond);

// The batch API on the same rays, kBatch at a time (as a bake hands it a probe's or a cache
// point's rays): the interleaved, prefetching walk against the one-ray loop above.
void traceBatches(benchmark::State& state, bool skirt, bool anyHit) {
    const int kernel = int(state.range(1)), set = int(state.range(0));
    if (!kernelRuns(state, kernel))
        return;
    const HeightfieldTracer& t = tracer(kernel, skirt);
    const Rays& r = rays(set);
    std::vector<TraceRay> batch(kRayCount);
    for (int k = 0; k < kRayCount; ++k)
        batch[size_t(k)] = {r.origin[size_t(k)], r.dir[size_t(k)], kInf};
    std::vector<RayHit> hits(kBatch);
    std::vector<uint8_t> found(kBatch);
    size_t next = 0;
    int64_t hitCount = 0;
    for (auto _ : state) {
        const std::span<const TraceRay> chunk(batch.data() + (next & (kRayCount - 1)), kBatch);
        next += kBatch;
        if (anyHit)
            t.occluded(chunk, found);
        else
            t.intersect(chunk, hits, found);
        benchmark::DoNotOptimize(found.data());
        benchmark::DoNotOptimize(hits.data());
        for (uint8_t f : found) hitCount += f;
    }
    const int64_t n = int64_t(state.iterations()) * kBatch;
    state.SetItemsProcessed(n);
    state.counters["hit_fraction"] = double(hitCount) / double(std::max<int64_t>(n, 1));
    state.SetLabel(std::string(kRaySetNames[set]) + "; batch; " + kKernelNames[kernel] + "; " + dem().source);
}

void BM_TracerBatch(benchmark::State& state) { traceBatches(state, true, false); }
BENCHMARK(BM_TracerBatch)->ArgNames({"rays", "kernel"})->ArgsProduct({{0, 1, 2}, {0, 1}})->Unit(benchmark::kMillisecond);

void BM_TracerBatchOccluded(benchmark::State& state) { traceBatches(state, true, true); }
BENCHMARK(BM_TracerBatchOccluded)->ArgNames({"rays", "kernel"})->ArgsProduct({{0, 1, 2}, {0, 1}})->Unit(benchmark::kMillisecond);

// Without the skirt: the batch's column beside Embree's (BM_Embree*1 trace the same triangles).
void BM_TracerBatchNoSkirt(benchmark::State& state) { traceBatches(state, false, false); }
BENCHMARK(BM_TracerBatchNoSkirt)->ArgNames({"rays", "kernel"})->ArgsProduct({{0, 1, 2}, {0, 1}})->Unit(benchmark::kMillisecond);

void BM_TracerBatchNoSkirtOccluded(benchmark::State& state) { traceBatches(state, false, true); }
BENCHMARK(BM_TracerBatchNoSkirtOccluded)->ArgNames({"rays", "kernel"})->ArgsProduct({{0, 1, 2}, {0, 1}})->Unit(benchmark::kMillisecond);

void BM_RayMarch(benchmark::State& state) {
    const Heightfield& hf = dem().hf;
    RayHit hit;
    runRays(state, kIncoherent, [&](const glm::vec3& o, const glm::vec3& d) {
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

#ifdef TERRALUX_HAVE_EMBREE
// Embree 3 on the same triangles as the tracer without its skirt: every vertex of the grid, two
// triangles per cell along the (c, r)-(c + 1, r + 1) diagonal of Heightfield.h.
std::atomic<int64_t> gEmbreeBytes{0}, gEmbreePeakBytes{0};
bool trackEmbreeMemory(void*, ssize_t bytes, bool) {
    const int64_t now = gEmbreeBytes += bytes;
    int64_t peak = gEmbreePeakBytes.load();
    while (now > peak && !gEmbreePeakBytes.compare_exchange_weak(peak, now)) {
    }
    return true;
}

struct EmbreeScene {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    explicit EmbreeScene(const Heightfield& hf) {
        device = rtcNewDevice("threads=1");
        rtcSetDeviceMemoryMonitorFunction(device, trackEmbreeMemory, nullptr);
        scene = rtcNewScene(device);
        rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        const int w = hf.width(), d = hf.depth();
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                              3 * sizeof(float), size_t(w) * size_t(d)));
        for (int r = 0; r < d; ++r)
            for (int c = 0; c < w; ++c) {
                const glm::vec3 p = hf.vertex(c, r);
                float* o = v + 3 * (size_t(r) * size_t(w) + size_t(c));
                o[0] = p.x, o[1] = p.y, o[2] = p.z;
            }
        auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
            g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), size_t(2) * (w - 1) * (d - 1)));
        const auto at = [w](int c, int r) { return unsigned(r * w + c); };
        size_t k = 0;
        for (int r = 0; r + 1 < d; ++r)
            for (int c = 0; c + 1 < w; ++c) {
                const unsigned a[6] = {at(c, r), at(c, r + 1), at(c + 1, r + 1), at(c, r), at(c + 1, r + 1), at(c + 1, r)};
                std::copy(a, a + 6, idx + 3 * k);
                k += 2;
            }
        rtcCommitGeometry(g);
        rtcAttachGeometry(scene, g);
        rtcReleaseGeometry(g);
        rtcCommitScene(scene);
    }
    ~EmbreeScene() {
        rtcReleaseScene(scene);
        rtcReleaseDevice(device);
    }
    RTCRay ray(const glm::vec3& o, const glm::vec3& d) const {
        RTCRay r{};
        r.org_x = o.x, r.org_y = o.y, r.org_z = o.z;
        r.dir_x = d.x, r.dir_y = d.y, r.dir_z = d.z;
        r.tnear = HeightfieldTracer::minDistance(o);
        r.tfar = kInf;
        r.mask = 0xffffffffu;
        return r;
    }
    bool intersect(const glm::vec3& o, const glm::vec3& d, float& t) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRayHit rh{};
        rh.ray = ray(o, d);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene, &context, &rh);
        t = rh.ray.tfar;
        return rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    }
    bool occluded(const glm::vec3& o, const glm::vec3& d) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRay r = ray(o, d);
        rtcOccluded1(scene, &context, &r);
        return r.tfar < 0.0f;
    }
};

const EmbreeScene& embree() {
    static const EmbreeScene e(dem().hf);
    return e;
}

void BM_EmbreeBuild(benchmark::State& state) {
    int64_t peak = 0;
    for (auto _ : state) {
        gEmbreePeakBytes = gEmbreeBytes.load();
        const int64_t before = gEmbreeBytes;
        EmbreeScene e(dem().hf);
        benchmark::DoNotOptimize(e.scene);
        peak = gEmbreePeakBytes - before;
    }
    state.counters["peak_MB"] = double(peak) / 1e6;
    state.SetLabel(dem().source);
}
BENCHMARK(BM_EmbreeBuild)->Iterations(2)->Unit(benchmark::kMillisecond);

void BM_EmbreeIntersect1(benchmark::State& state) {
    const EmbreeScene& e = embree();
    runRays(state, int(state.range(0)), [&](const glm::vec3& o, const glm::vec3& d) {
        float t;
        return e.intersect(o, d, t);
    });
}
BENCHMARK(BM_EmbreeIntersect1)->ArgName("rays")->DenseRange(0, 2)->Unit(benchmark::kMillisecond);

void BM_EmbreeOccluded1(benchmark::State& state) {
    const EmbreeScene& e = embree();
    runRays(state, int(state.range(0)), [&](const glm::vec3& o, const glm::vec3& d) { return e.occluded(o, d); });
}
BENCHMARK(BM_EmbreeOccluded1)->ArgName("rays")->DenseRange(0, 2)->Unit(benchmark::kMillisecond);

// The tracer without its skirt on the same rays, the fair opponent of the two above.
void BM_TracerNoSkirt(benchmark::State& state) { traceRays(state, false, false); }
BENCHMARK(BM_TracerNoSkirt)->ArgNames({"rays", "kernel"})->ArgsProduct({{0, 1, 2}, {0, 1}})->Unit(benchmark::kMillisecond);

void BM_TracerNoSkirtOccluded(benchmark::State& state) { traceRays(state, false, true); }
BENCHMARK(BM_TracerNoSkirtOccluded)->ArgNames({"rays", "kernel"})->ArgsProduct({{0, 1, 2}, {0, 1}})->Unit(benchmark::kMillisecond);

// Every ray of a set through both: hit/miss disagreements, and distances that differ by more
// than 1 mm + 1e-4 t (Embree's vertices are floats; the tracer's grid is exact in double).
void BM_CompareEmbree(benchmark::State& state) {
    const EmbreeScene& e = embree();
    const HeightfieldTracer& t = tracerNoSkirt();
    const Rays& r = rays(int(state.range(0)));
    int64_t hits = 0, hitMiss = 0, tMismatch = 0;
    double maxDiff = 0;
    for (auto _ : state) {
        for (int k = 0; k < kRayCount; ++k) {
            RayHit a;
            float tb = 0;
            const bool ha = t.intersect(r.origin[k], r.dir[k], kInf, a);
            const bool hb = e.intersect(r.origin[k], r.dir[k], tb);
            hits += ha;
            hitMiss += ha != hb;
            if (ha && hb) {
                tMismatch += std::fabs(a.t - tb) > 1e-3f + 1e-4f * a.t;
                maxDiff = std::max(maxDiff, double(std::fabs(a.t - tb)));
            }
        }
    }
    state.counters["rays"] = kRayCount;
    state.counters["tracer_hits"] = double(hits);
    state.counters["hit_miss_disagree"] = double(hitMiss);
    state.counters["t_disagree"] = double(tMismatch);
    state.counters["max_t_diff_m"] = maxDiff;
    state.SetLabel(std::string(kRaySetNames[state.range(0)]) + "; " + dem().source);
}
BENCHMARK(BM_CompareEmbree)->ArgName("rays")->DenseRange(0, 2)->Iterations(1)->Unit(benchmark::kMillisecond);
#endif

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

// The void fill of DEM import, by GDAL alone (range(1) == 0) or by the membrane (1).
void BM_VoidFillLargeHole(benchmark::State& state) {
    const HoleCase hole = roundHole(int(state.range(0)));
    const VoidFill method = state.range(1) ? VoidFill::Membrane : VoidFill::Gdal;
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

// The nodata collars a reprojection outside Terralux leaves: a square grid turned by 2 degrees
// (the grid convergence of a UTM zone's edge at 42 N) inside a north-up one, about 4 % of its
// cells in four thin wedges along the edges. GDAL's search walks the grid's side for each of
// them; the membrane's cost is linear in the cells.
void BM_VoidFillCollars(benchmark::State& state) {
    const int n = int(state.range(0));
    std::vector<float> field(size_t(n) * n);
    std::vector<uint8_t> mask(field.size(), 0);
    const double c = 0.5 * (n - 1), turn = 2.0 * 3.14159265358979323846 / 180.0;
    const double half = c / (std::cos(turn) + std::sin(turn));  // the turned square's half side
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            field[size_t(y) * n + x] = float(1500 + 600 * std::sin(0.004 * x) * std::cos(0.003 * y));
            const double u = std::cos(turn) * (x - c) + std::sin(turn) * (y - c);
            const double v = -std::sin(turn) * (x - c) + std::cos(turn) * (y - c);
            mask[size_t(y) * n + x] = std::max(std::fabs(u), std::fabs(v)) > half;
        }
    const VoidFill method = state.range(1) ? VoidFill::Membrane : VoidFill::Gdal;
    for (auto _ : state) {
        std::vector<float> g = field;
        terralux::fillVoids(g, n, n, mask, method);
        benchmark::DoNotOptimize(g.data());
    }
    state.counters["nodata_share"] = double(std::count(mask.begin(), mask.end(), uint8_t(1))) / double(mask.size());
}
BENCHMARK(BM_VoidFillCollars)
    ->Args({1200, 0})
    ->Args({1200, 1})
    ->Args({2400, 0})
    ->Args({2400, 1})
    ->Args({4800, 1})
    ->ArgNames({"side", "membrane"})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

// The membrane solve alone on the same holes, from GDAL's fill (range(1) == 0) or from the
// mean of the hole's rim, as the import starts it (1).
void BM_MembraneSolve(benchmark::State& state) {
    const HoleCase hole = roundHole(int(state.range(0)));
    std::vector<float> start = hole.field;
    const MembraneStart from = state.range(1) ? MembraneStart::RimMean : MembraneStart::Heights;
    if (from == MembraneStart::Heights) terralux::fillVoids(start, hole.n, hole.n, hole.mask, VoidFill::Gdal);
    MembraneReport report;
    for (auto _ : state) {
        std::vector<float> g = start;
        report = terralux::membraneFill(g, hole.n, hole.n, hole.mask, from);
        benchmark::DoNotOptimize(g.data());
    }
    state.counters["iterations"] = double(report.iterations);
}
BENCHMARK(BM_MembraneSolve)
    ->ArgsProduct({{300, 1000, 2000}, {0, 1}})
    ->ArgNames({"hole", "rim_start"})
    ->Iterations(2)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace terralux
