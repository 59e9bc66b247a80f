// Horizon ambient occlusion (renderer/terrain/HorizonAO.h) against the bake's ray tracer, and its
// cost, on the shared N42E001 SRTM tile (reprojected to UTM as the import does). Needs the shared
// data beside the repository; exits 0 with a note when it is absent. Prints markdown tables.
//
// Reference: cosine-weighted sky visibility traced by HeightfieldTracer with the skirt off (only
// the footprint occludes, as in the AO), 4096 rays per point on the stratified Fibonacci spiral
// of SphereSampling.h, turned by a per-point offset. Two comparisons, each with its own method's
// normal on both sides:
//   points:   horizonSkyVisibilityAt at random points, triangle normal (Heightfield::surfaceNormal);
//   vertices: the field of horizonSkyVisibility at random vertices, vertex normal.
// Cost of the field is measured on the tile and on the tile upsampled 3x each way (bilinear),
// about 12 M vertices, the size of a 1" tile; so is the sun's horizon map of the shadows.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <numbers>
#include <utility>
#include <random>
#include <vector>

#include <tbb/parallel_for.h>

#include "DemImport.h"
#include "bake/DiffuseBake.h"
#include "bake/HeightfieldTracer.h"
#include "bake/Sky.h"
#include "bake/SphereSampling.h"
#include "terrain/HorizonAO.h"

using namespace terralux;

namespace {

constexpr int kPoints = 1024;
constexpr uint32_t kRays = 4096;
constexpr double kMargin = 2000.0;  // metres between the points and the border

double seconds(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct Sample {
    float x, z;
    int col = -1, row = -1;  // a vertex, for the field comparison
};

Heightfield upsampled3(const Heightfield& hf) {
    const int w = 3 * (hf.width() - 1) + 1, d = 3 * (hf.depth() - 1) + 1;
    std::vector<float> h(size_t(w) * size_t(d));
    tbb::parallel_for(0, d, [&](int r) {
        for (int c = 0; c < w; ++c) {
            const int c0 = std::min(c / 3, hf.width() - 2), r0 = std::min(r / 3, hf.depth() - 2);
            const float fx = (c - 3 * c0) / 3.0f, fz = (r - 3 * r0) / 3.0f;
            h[size_t(r) * w + c] = (1 - fz) * ((1 - fx) * hf.at(c0, r0) + fx * hf.at(c0 + 1, r0)) +
                                   fz * ((1 - fx) * hf.at(c0, r0 + 1) + fx * hf.at(c0 + 1, r0 + 1));
        }
    });
    return Heightfield(w, d, hf.cellSizeX() / 3.0, hf.cellSizeZ() / 3.0, std::move(h));
}

}  // namespace

int main() {
    const std::filesystem::path path = std::filesystem::path(TERRALUX_SHARED_DATA) / "dem" / "N42E001.hgt";
    if (!std::filesystem::exists(path)) {
        std::printf("SKIP: shared DEM N42E001.hgt not present\n");
        return 0;
    }
    const Heightfield hf = importDem(path.string()).heightfield;
    const HeightfieldTracer tracer(hf, HeightfieldTracer::Options{false});
    std::printf("N42E001: %d x %d vertices, cells %.1f x %.1f m; %d points at least %.0f m inside the border, "
                "%u rays each\n\n",
                hf.width(), hf.depth(), hf.cellSizeX(), hf.cellSizeZ(), kPoints, kMargin, kRays);

    std::mt19937 rng(20240611);
    std::uniform_real_distribution<float> ux(hf.minX() + kMargin, hf.maxX() - kMargin);
    std::uniform_real_distribution<float> uz(hf.minZ() + kMargin, hf.maxZ() - kMargin);
    std::vector<Sample> points(kPoints), vertices(kPoints);
    for (Sample& s : points) s = {ux(rng), uz(rng)};
    for (Sample& s : vertices) {
        s.col = int(std::lround(ux(rng) / hf.cellSizeX() + 0.5 * (hf.width() - 1)));
        s.row = int(std::lround(uz(rng) / hf.cellSizeZ() + 0.5 * (hf.depth() - 1)));
        s.x = hf.xOf(s.col);
        s.z = hf.zOf(s.row);
    }

    auto t0 = std::chrono::steady_clock::now();
    std::vector<float> refPoints(kPoints), refVertices(kPoints);
    tbb::parallel_for(0, kPoints, [&](int i) {
        const Sample& p = points[size_t(i)];
        refPoints[size_t(i)] = tracedSkyVisibility(tracer, {p.x, hf.surfaceHeight(p.x, p.z), p.z},
                                                hf.surfaceNormal(p.x, p.z), kRays, uint32_t(i));
        const Sample& v = vertices[size_t(i)];
        refVertices[size_t(i)] = tracedSkyVisibility(tracer, hf.vertex(v.col, v.row), hf.vertexNormal(v.col, v.row),
                                                  kRays, uint32_t(i + kPoints));
    });
    const double refSeconds = seconds(t0);
    // The reference's own error: the same points at 4x the rays.
    double refNoise = 0.0;
    constexpr int kNoisePoints = 128;
    std::vector<float> fine(kNoisePoints);
    tbb::parallel_for(0, kNoisePoints, [&](int i) {
        const Sample& p = points[size_t(i)];
        fine[size_t(i)] = tracedSkyVisibility(tracer, {p.x, hf.surfaceHeight(p.x, p.z), p.z},
                                           hf.surfaceNormal(p.x, p.z), 4 * kRays, uint32_t(i) + 77777u);
    });
    for (int i = 0; i < kNoisePoints; ++i) refNoise += std::fabs(fine[size_t(i)] - refPoints[size_t(i)]);
    refNoise /= kNoisePoints;
    double meanVis = 0.0;
    for (float v : refPoints) meanVis += v;
    std::printf("reference: %.1f s; mean visibility %.3f; mean |4096 rays - 16384 rays| = %.5f (%d points)\n\n",
                refSeconds, meanVis / kPoints, refNoise, kNoisePoints);

    const Heightfield big = upsampled3(hf);
    std::printf("| directions | points: mean \\|err\\| | max \\|err\\| | ms per point | vertices: mean \\|err\\| | "
                "max \\|err\\| | field %.2f M vertices (s) | field %.1f M vertices (s) |\n",
                hf.heights().size() / 1e6, big.heights().size() / 1e6);
    std::printf("|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (const int k : {8, 16, 32, 64}) {
        const HorizonAoSettings settings{k, 0.0};
        std::vector<float> at(kPoints);
        t0 = std::chrono::steady_clock::now();
        for (int i = 0; i < kPoints; ++i)
            at[size_t(i)] = horizonSkyVisibilityAt(hf, settings, points[size_t(i)].x, points[size_t(i)].z);
        const double perPointMs = 1e3 * seconds(t0) / kPoints;

        t0 = std::chrono::steady_clock::now();
        const std::vector<float> field = horizonSkyVisibility(hf, settings);
        const double fieldSeconds = seconds(t0);
        t0 = std::chrono::steady_clock::now();
        const std::vector<float> bigField = horizonSkyVisibility(big, settings);
        const double bigSeconds = seconds(t0);

        double meanP = 0, maxP = 0, meanV = 0, maxV = 0;
        for (int i = 0; i < kPoints; ++i) {
            const double ep = std::fabs(at[size_t(i)] - refPoints[size_t(i)]);
            const Sample& v = vertices[size_t(i)];
            const double ev = std::fabs(field[size_t(v.row) * hf.width() + v.col] - refVertices[size_t(i)]);
            meanP += ep;
            maxP = std::max(maxP, ep);
            meanV += ev;
            maxV = std::max(maxV, ev);
        }
        std::printf("| %d | %.4f | %.4f | %.3f | %.4f | %.4f | %.2f | %.2f |\n", k, meanP / kPoints, maxP, perPointMs,
                    meanV / kPoints, maxV, fieldSeconds, bigSeconds);
        std::fflush(stdout);
    }

    // The sun's horizon map (shadows.heightfield): one sweep in the sun's azimuth, skirt on, as
    // the viewport runs it when the sun moves.
    std::printf("\n| sun elevation, azimuth | sun horizon map %.2f M vertices (ms) | %.1f M vertices (ms) |\n",
                hf.heights().size() / 1e6, big.heights().size() / 1e6);
    std::printf("|---|---:|---:|\n");
    for (const auto& [elevation, azimuth] : {std::pair{5.0, 135.0}, std::pair{12.0, 17.0}, std::pair{35.0, 270.0}}) {
        const glm::vec3 sun = sunDirection(azimuth, elevation);
        const float radius = float(0.27 * std::numbers::pi / 180.0);
        double best = 1e9, bestBig = 1e9;
        for (int rep = 0; rep < 3; ++rep) {
            t0 = std::chrono::steady_clock::now();
            (void)sunHorizonVisibility(hf, sun, radius, true);
            best = std::min(best, seconds(t0));
            t0 = std::chrono::steady_clock::now();
            (void)sunHorizonVisibility(big, sun, radius, true);
            bestBig = std::min(bestBig, seconds(t0));
        }
        std::printf("| %.0f°, %.0f° | %.0f | %.0f |\n", elevation, azimuth, 1e3 * best, 1e3 * bestBig);
    }
    return 0;
}
