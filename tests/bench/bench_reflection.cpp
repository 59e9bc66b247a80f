// Reflection probes (docs/lighting.md, "Reflection probes"): what each encoding costs and how far
// it is from the reference, over cube sizes and rays per texel, on the embedded sample and on the
// shared N42E001 tile (reduced to 512 samples a side; skipped when the shared data is absent).
// Prints markdown tables. The lighting is the default project's (sun at 35°, uniform sky, the
// height ramp), the light on the terrain from a standard-preset irradiance cache, 4 × 4 probes.
//
// Error: measureReflectionError, relative RMS of prefiltered radiance luminance over 256
// directions against a reference cube at 4× the resolution a side with the same rays per texel,
// brute-force prefiltered; mean and max over the probes at roughness 0.25 and 1.
#include <chrono>
#include <cstdio>
#include <filesystem>

#include <tbb/info.h>

#include "Project.h"
#include "ReflectionProbeFile.h"
#include "SceneLighting.h"
#include "TerrainLoading.h"
#include "bake/HeightfieldTracer.h"
#include "bake/ReflectionBake.h"

using namespace terralux;

namespace {

double seconds(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void run(const char* name, Project project) {
    const DemImportResult terrain = loadProjectTerrain(project);
    const Heightfield& hf = terrain.heightfield;
    BakeLighting lighting = lightingOf(project, hf);
    const HeightfieldTracer tracer(hf);
    lighting.tracer = &tracer;
    lighting.surface = surfaceAlbedoOf(project, hf);
    const BakeQuality q = qualityPreset(QualityPreset::Standard);
    const IrradianceCache cache(lighting, q.cacheResolution, q.cacheRays, q.sunSamples, q.bounces - 1, {});
    ReflectionProbeSettings s;
    s.enabled = true;
    const ReflectionLayout layout = placeReflectionProbes(s, hf);
    const ReflectionLighting light{&lighting, &cache, q.bounces, groundRadiance(lighting, s.groundColor)};

    std::printf("\n**%s**: %d x %d samples, 4 x 4 probes, %d threads\n\n", name, hf.width(), hf.depth(),
                tbb::info::default_concurrency());
    std::printf("| cube | rays/texel | bake | rays | .rprobe cubemap | faces | cubemap r 0.25 mean / max | faces r 0.25 mean / max | cubemap r 1 mean / max | faces r 1 mean / max |\n");
    std::printf("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (int resolution : {8, 16, 32})
        for (int rays : {4, 16}) {
            s.resolution = resolution;
            s.rayCount = rays;
            const auto t0 = std::chrono::steady_clock::now();
            uint64_t traced = 0;
            ReflectionProbeSet set = bakeReflectionProbes(light, s, layout, 1, {}, &traced);
            const double bake = seconds(t0);
            const size_t cubeBytes = encodeReflectionProbes(set).size();
            const ReflectionErrorReport e = measureReflectionError(light, s, set, {0.25f, 1.0f}, 1, {});
            toEncoding(set, ReflectionEncoding::Faces);
            const size_t faceBytes = encodeReflectionProbes(set).size();
            const auto& lo = e.byRoughness[0];
            const auto& hi = e.byRoughness[1];
            std::printf("| %d² | %d | %.2f s | %.1f M | %.0f kB | %.1f kB | %.2f / %.2f %% | %.1f / %.1f %% | %.2f / %.2f %% | %.1f / %.1f %% |\n",
                        resolution, rays, bake, double(traced) / 1e6, double(cubeBytes) / 1e3, double(faceBytes) / 1e3,
                        100 * lo.cubemap.mean, 100 * lo.cubemap.max, 100 * lo.faces.mean, 100 * lo.faces.max,
                        100 * hi.cubemap.mean, 100 * hi.cubemap.max, 100 * hi.faces.mean, 100 * hi.faces.max);
            std::fflush(stdout);
        }
}

}  // namespace

int main() {
    run("Embedded sample", Project{});
    const std::filesystem::path tile = std::filesystem::path(TERRALUX_SHARED_DATA) / "dem" / "N42E001.hgt";
    if (!std::filesystem::exists(tile)) {
        std::printf("\nSKIP: shared DEM N42E001.hgt not present\n");
        return 0;
    }
    Project p;
    p.scene.terrain.dem = tile.string();
    p.scene.terrain.maxResolution = 512;
    run("N42E001", p);
    return 0;
}
