// Uniform vs adaptive vs error-driven probe placement on two real DEMs (the committed crops of
// Big Tujunga, 30 m, and the Pica d'Estats massif, SRTM reprojected to 81 m): probe count, .shprobe
// bytes, bake time and interpolation error (docs/lighting.md), printed as the markdown table of the
// README. The bake is the standard preset with the project's default sun, sky and albedo; the
// uniform grid is the octree with max_cell_size = min_cell_size (same box, same rules near the
// ground, every cell its own probe). Times exclude the irradiance cache, which every placement
// shares (its time is printed per DEM).
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <optional>
#include <string>

#include <tbb/info.h>

#include "DemImport.h"
#include "bake/AdaptivePlacement.h"
#include "bake/DiffuseBake.h"
#include "bake/PhysicalSky.h"
#include "scene/SceneDescription.h"

using namespace terralux;

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

constexpr int kErrorPoints = 1024;

struct Row {
    std::string placement;
    ProbeVolumeSettings volume;
};

void benchDem(const char* label, const std::filesystem::path& file) {
    const DemImportResult dem = importDem(file.string());
    const Heightfield& hf = dem.heightfield;
    const SceneDescription scene;  // the documented defaults
    const HeightfieldTracer tracer(hf);
    BakeLighting L;
    L.tracer = &tracer;
    L.sky = Sky::uniform(scene.sky.uniformRadiance());
    L.sun.direction = sunDirection(scene.sun.azimuthDeg, scene.sun.elevationDeg);
    L.sun.illuminance = scene.sun.color * sceneUnitsOfLux(scene.sun.illuminance);
    L.sun.angularRadius = float(scene.sun.angularRadiusDeg * std::numbers::pi / 180.0);
    L.albedo = scene.terrain.albedo;
    const BakeQuality q = qualityPreset(QualityPreset::Standard);
    const auto cacheStart = Clock::now();
    const IrradianceCache cache(L, q.cacheResolution, q.cacheRays, q.sunSamples, q.bounces - 1, {});
    const double cacheSeconds = since(cacheStart);
    const ProbeBaker baker = seededBaker(L, &cache, q.bounces, q.rays, 0x7E77A1ABull, {});

    ProbeVolumeSettings adaptive;
    adaptive.placement = ProbePlacement::Adaptive;
    const double cell = std::max(hf.cellSizeX(), hf.cellSizeZ());
    ProbeVolumeSettings uniform = adaptive;
    uniform.adaptive.maxCellSize = cell;
    std::vector<Row> rows = {{"uniform", uniform}, {"adaptive", adaptive}};
    for (double tolerance : {0.05, 0.03, 0.02}) {
        ProbeVolumeSettings v = adaptive;
        v.adaptive.tolerance = tolerance;
        char name[64];
        std::snprintf(name, sizeof name, "error-driven %.0f %%", 100.0 * tolerance);
        rows.push_back({name, v});
    }

    std::printf("\n%s: %d x %d samples of %.1f m, relief %.0f m; cells %.1f m to %.1f m, "
                "standard preset (%d rays, %d bounces), irradiance cache %.2f s, %d threads\n\n",
                label, hf.width(), hf.depth(), cell, hf.maxHeight() - hf.minHeight(), cell,
                16.0 * cell, q.rays, q.bounces, cacheSeconds, tbb::info::default_concurrency());
    std::printf("| placement | probes | of uniform | .shprobe bytes | bake s | "
                "error mean | error p95 | error max | within tolerance |\n");
    std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    std::fflush(stdout);
    size_t uniformProbes = 0;
    for (const Row& row : rows) {
        const auto t = Clock::now();
        const AdaptiveBake a = bakeAdaptive(row.volume, hf, baker);
        const double seconds = since(t);
        if (uniformProbes == 0) uniformProbes = a.layout.validCount();
        const std::optional<double> tolerance = row.volume.adaptive.tolerance;
        const InterpolationError e =
            measureInterpolationError(a.layout, a.bake.sh, hf, baker, kErrorPoints, 2024, tolerance);
        char within[32] = "-";
        if (tolerance) std::snprintf(within, sizeof within, "%.1f %%", 100.0 * *e.withinTolerance);
        std::printf("| %s | %zu | %.1f %% | %llu | %.1f | %.2f %% | %.2f %% | %.1f %% | %s |\n",
                    row.placement.c_str(), a.layout.validCount(),
                    100.0 * double(a.layout.validCount()) / double(uniformProbes),
                    (unsigned long long)a.layout.fileBytes(), seconds, 100.0 * e.mean,
                    100.0 * e.p95, 100.0 * e.max, within);
        std::fflush(stdout);
    }
}

}  // namespace

int main() {
    const std::filesystem::path dems = std::filesystem::path(TERRALUX_TEST_DATA) / "dem";
    std::printf("Interpolation error: relative RMS of irradiance over 256 normals at %d points "
                "drawn uniformly from the volume above the terrain, trilinear over the .shprobe "
                "cells against a probe baked there.\n",
                kErrorPoints);
    benchDem("Big Tujunga (bigtujunga_utm11_crop.tif)", dems / "bigtujunga_utm11_crop.tif");
    benchDem("Pica d'Estats (n42e001_voids_crop.tif)", dems / "n42e001_voids_crop.tif");
    return 0;
}
