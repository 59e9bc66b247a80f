// Placement against an accuracy (probe_volumes[].target_error, docs/lighting.md "Asking for an
// accuracy"): for targets of 10, 5 and 3 %, the coarsest uniform terrain grid that meets each, the
// adaptive octree and the surface quadtree that target_error chooses, on every committed DEM crop
// and, when the shared data is present, on every shared DEM resampled to kSharedMaxResolution.
// Printed as the markdown table of docs/accuracy.md ("Placements at the same error").
//
// Every placement is baked by runBake (the TERRALUX_BENCH_QUALITY preset, draft by default,
// kThreads threads, the project's default lighting), its .shprobe read back and interpolated as the
// engine reads it, at the same points: kPointsPerSide² over the DEM, kHeight metres above the
// ground, against a probe baked there with the same model at kTruthRays rays. The bakes' own error
// maps are not comparable across placements (a terrain grid measures at its probe height, an
// octree at 2 % of a cell).
//
// The uniform grid is found by searchTerrainGrid within the 4096-probe terrain-grid limit that
// every bake enforces; where no grid within it meets the target, the densest stands for it and the
// surface / uniform ratio is an upper bound ("< ...").
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "BakeJob.h"
#include "Project.h"
#include "SceneLighting.h"
#include "ShProbeFile.h"
#include "TerrainLoading.h"
#include "bake/AdaptivePlacement.h"
#include "bake/DiffuseBake.h"
#include "bake/HeightfieldTracer.h"
#include "bake/SphereSampling.h"
#include "bake/TargetSearch.h"

using namespace terralux;

namespace {

constexpr int kThreads = 2;
constexpr int kSharedMaxResolution = 256;
constexpr int kPointsPerSide = 32;
constexpr float kHeight = 5.0f;  // the terrain grid's default height_offset
constexpr int kTruthRays = 1024;
constexpr double kTargets[] = {0.10, 0.05, 0.03};

// TERRALUX_BENCH_QUALITY (draft, standard, high) picks the preset; draft by default.
std::string qualityName() {
    const char* q = std::getenv("TERRALUX_BENCH_QUALITY");
    return q && *q ? q : "draft";
}

struct Dem {
    std::string name;
    std::filesystem::path file;
    int maxResolution = 0;  // 0: as committed
};

// The points every placement is judged at, and the truth there.
struct CommonPoints {
    std::vector<glm::vec3> points;
    std::vector<sh::ShRgb> truth;
    // p95 of a draft probe baked at each point itself: the Monte Carlo floor no placement beats.
    double floor = 0.0;
};

struct Baked {
    nlohmann::json volume;  // bake_report.json volumes[0]
    double seconds = 0.0;   // the whole bake, search included
    size_t probes = 0;
    uint64_t bytes = 0;
    double p95 = 0.0;       // on the common points
    size_t uncovered = 0;   // common points no probe covers (the engine falls back)
};

Project projectFor(const Dem& dem, const std::filesystem::path& out) {
    nlohmann::json doc = defaultProjectJson();
    doc["terrain"]["dem"] = dem.file.string();
    doc["terrain"]["max_resolution"] = dem.maxResolution;
    doc["bake"]["quality"] = qualityName();
    doc["export"]["out_dir"] = out.string();
    Project p;
    p.scene = sceneFromJson(doc, "bench", nullptr);
    return p;
}

CommonPoints commonPoints(const Project& project, const Heightfield& hf) {
    CommonPoints c;
    const float stepX = (hf.maxX() - hf.minX()) / kPointsPerSide, stepZ = (hf.maxZ() - hf.minZ()) / kPointsPerSide;
    for (int j = 0; j < kPointsPerSide; ++j)
        for (int i = 0; i < kPointsPerSide; ++i) {
            const float x = hf.minX() + (float(i) + 0.5f) * stepX, z = hf.minZ() + (float(j) + 0.5f) * stepZ;
            c.points.emplace_back(x, hf.surfaceHeight(x, z) + kHeight, z);
        }
    BakeLighting lighting = lightingOf(project, hf);
    const HeightfieldTracer tracer(hf, HeightfieldTracer::Options{project.scene.terrain.skirt});
    lighting.tracer = &tracer;
    lighting.water = bakeWaterOf(project, hf);
    lighting.surface = surfaceAlbedoOf(project, hf);
    const BakeQuality q = qualityOf(project.scene.bake);
    const IrradianceCache cache(lighting, q.cacheResolution, q.cacheRays, q.sunSamples, q.bounces - 1, {});
    // Windowed as the written probes are, so the difference is interpolation (and probe noise).
    auto baker = [&](int rays, uint64_t seed) {
        return deringedBaker(seededBaker(lighting, &cache, q.bounces, rays, seed, {}), project.scene.bake.deringing);
    };
    std::vector<uint64_t> keys(c.points.size());
    for (size_t k = 0; k < keys.size(); ++k) keys[k] = splitmix64(k);
    c.truth = baker(kTruthRays, 0xC0111011ull)(c.points, keys).sh;
    const std::vector<sh::ShRgb> draft = baker(q.rays, 0xD4AF7ull)(c.points, keys).sh;
    std::vector<float> errors;
    for (size_t k = 0; k < draft.size(); ++k) errors.push_back(relativeIrradianceError(draft[k], c.truth[k]));
    c.floor = spreadOf(std::move(errors)).p95;
    return c;
}

// The relative irradiance error of a .shprobe at the common points, interpolated as the engine
// reads the file (interpolateProbes over its occupancy grid).
void measure(const std::filesystem::path& shprobe, const CommonPoints& c, Baked& b) {
    const ShProbeGrid g = readShProbeFile(shprobe);
    ProbeLayout L;
    L.cellDims = {g.dims.x, g.dims.y, g.dims.z};
    L.cellOrigin = g.origin;
    L.cellSize = g.spacing;
    L.cellProbe = g.occupancy;
    std::vector<sh::ShRgb> sh(g.probes.size());
    for (size_t i = 0; i < sh.size(); ++i) sh[i].c = g.probes[i].coeffs;
    std::vector<float> errors;
    for (size_t k = 0; k < c.points.size(); ++k) {
        sh::ShRgb value;
        if (interpolateProbes(L, sh, c.points[k], value)) errors.push_back(relativeIrradianceError(value, c.truth[k]));
        else ++b.uncovered;
    }
    b.p95 = spreadOf(std::move(errors)).p95;
}

Baked bake(Project project, const CommonPoints& c) {
    BakeRequest request;
    request.project = std::move(project);
    request.threads = kThreads;
    const auto start = std::chrono::steady_clock::now();
    const BakeOutcome o = runBake(request, {}, nullptr);
    Baked b;
    b.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    b.volume = o.report["volumes"][0];
    b.probes = b.volume["probes"].get<size_t>();
    b.bytes = b.volume["bytes"].get<uint64_t>();
    const auto shprobe = std::find_if(o.files.begin(), o.files.end(),
                                      [](const std::filesystem::path& f) { return f.extension() == ".shprobe"; });
    if (shprobe == o.files.end()) throw std::runtime_error("the bake wrote no .shprobe");
    measure(*shprobe, c, b);
    return b;
}

std::string dimsOf(const std::array<int, 3>& d) { return std::to_string(d[0]) + "x" + std::to_string(d[2]); }

// One placement's cells of the table: probes, bytes, bake seconds, p95 (and whether it met).
std::string cells(const Baked& b, double target) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "%zu | %llu | %.1f | %.1f %%%s", b.probes, (unsigned long long)b.bytes, b.seconds,
                  100.0 * b.p95, b.p95 <= target ? "" : " (misses)");
    return buf;
}

void benchDem(const Dem& dem, const std::filesystem::path& out) {
    const Project base = projectFor(dem, out);
    const Heightfield hf = loadProjectTerrain(base).heightfield;
    const auto t0 = std::chrono::steady_clock::now();
    const CommonPoints c = commonPoints(base, hf);
    std::fprintf(stderr, "%s: %d x %d samples, truth at %zu points in %.1f s\n", dem.name.c_str(), hf.width(),
                 hf.depth(), c.points.size(),
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    // Uniform grids by dims, shared by the targets' searches.
    std::map<std::array<int, 3>, Baked> uniform;
    auto uniformBake = [&](const std::array<int, 3>& dims) -> const Baked& {
        auto it = uniform.find(dims);
        if (it != uniform.end()) return it->second;
        Project p = base;
        p.scene.probeVolumes[0].gridDims = dims;
        return uniform.emplace(dims, bake(std::move(p), c)).first->second;
    };
    // A placement that missed a target at its budget misses every smaller one: not baked again.
    std::optional<Baked> octreeMissed, surfaceMissed;
    int start = 8;
    for (const double target : kTargets) {
        const PlacementSearch s = searchTerrainGrid(hf, target, kMaxTerrainGridProbes, start,
                                                    [&](const std::array<int, 3>& dims) {
                                                        const Baked& u = uniformBake(dims);
                                                        PlacementTrial trial;
                                                        trial.dims = dims;
                                                        trial.probes = u.probes;
                                                        trial.bytes = u.bytes;
                                                        trial.p95 = u.p95;
                                                        return trial;
                                                    });
        start = std::max(s.chosen.dims[0], s.chosen.dims[2]);
        const Baked& u = uniform.at(s.chosen.dims);
        auto placed = [&](ProbePlacement placement, std::optional<Baked>& missed) {
            if (missed) return *missed;
            Project p = base;
            p.scene.probeVolumes[0].placement = placement;
            p.scene.probeVolumes[0].targetError = target;
            Baked b = bake(std::move(p), c);
            if (b.p95 > target && b.volume["target"]["capped"].get<bool>()) missed = b;
            return b;
        };
        const Baked a = placed(ProbePlacement::Adaptive, octreeMissed);
        const Baked f = placed(ProbePlacement::Surface, surfaceMissed);
        const char* bound = s.met ? "" : "< ";
        std::printf("| %s | %.1f %% | %.0f %% | %s%s | %s | %s | %s | %s%.2f |\n", dem.name.c_str(), 100.0 * c.floor,
                    100.0 * target, dimsOf(s.chosen.dims).c_str(), s.met ? "" : " (densest)", cells(u, target).c_str(),
                    cells(a, target).c_str(), cells(f, target).c_str(), bound, double(f.probes) / double(u.probes));
        std::fflush(stdout);
        if (a.uncovered + f.uncovered + u.uncovered > 0)
            std::fprintf(stderr, "%s %.0f %%: uncovered points: octree %zu, surface %zu, uniform %zu\n",
                         dem.name.c_str(), 100.0 * target, a.uncovered, f.uncovered, u.uncovered);
    }
}

}  // namespace

int main() {
    const std::filesystem::path crops = std::filesystem::path(TERRALUX_TEST_DATA) / "dem";
    const std::filesystem::path shared = std::filesystem::path(TERRALUX_SHARED_DATA) / "dem";
    std::vector<Dem> dems = {{"bigtujunga_utm11_crop.tif", crops / "bigtujunga_utm11_crop.tif"},
                             {"rainier_crop.tif", crops / "rainier_crop.tif"},
                             {"n42e001_voids_crop.tif", crops / "n42e001_voids_crop.tif"},
                             {"orkhon_crop.asc", crops / "orkhon_crop.asc"}};
    if (std::filesystem::is_directory(shared)) {
        for (const char* f : {"N42E001.hgt", "mt_rainier_90m.tif", "srtm_bigtujunga30m_utm11.tif",
                              "topotoolbox_exampleDEM.asc"})
            if (std::filesystem::exists(shared / f)) dems.push_back({std::string(f) + " @" + std::to_string(kSharedMaxResolution),
                                                                     shared / f, kSharedMaxResolution});
    } else {
        std::printf("shared DEMs not present (%s): committed crops only\n", shared.string().c_str());
    }
    const std::filesystem::path out = std::filesystem::temp_directory_path() / "terralux_bench_target";
    std::printf("%s quality, %d threads; p95 of the relative irradiance error at %d x %d points %.0f m above the "
                "ground, each .shprobe interpolated as the engine reads it against a probe baked there at %d rays. "
                "Uniform: the coarsest terrain grid that meets the target within the %d-probe terrain-grid limit; "
                "where none does, the densest, and the ratio is an upper bound. Octree and surface: target_error. "
                "Floor: the p95 of a probe of the preset baked at each point itself. "
                "Times: the whole bake, target search included.\n\n",
                qualityName().c_str(), kThreads, kPointsPerSide, kPointsPerSide, double(kHeight), kTruthRays,
                kMaxTerrainGridProbes);
    std::printf("| DEM | floor p95 | target | uniform grid | probes | bytes | bake s | p95 | octree probes | bytes | "
                "bake s | p95 | surface probes | bytes | bake s | p95 | surface / uniform probes |\n");
    std::printf("|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    std::fflush(stdout);
    for (const Dem& d : dems) benchDem(d, out);
    std::filesystem::remove_all(out);
    return 0;
}
