// Target-driven placement (probe_volumes[].target_error, docs/lighting.md "Asking for an accuracy")
// against a uniform terrain grid at the same error, on every committed DEM crop and, when the
// shared data is present, on every shared DEM resampled to kSharedMaxResolution. Printed as the
// markdown table of the README ("Adaptive against uniform at the same error").
//
// Every placement is baked by runBake (draft quality, kThreads threads, the project's default
// lighting), its .shprobe read back and interpolated as the engine reads it, at the same points:
// kPointsPerSide² over the DEM, kHeight metres above the ground, against a probe baked there with
// the draft model at kTruthRays rays. The bakes' own error maps are not comparable across
// placements (a terrain grid measures at its probe height, an adaptive volume at 2 % of a cell).
//
// The uniform grid is the coarsest terrain grid (probes per side bisected by searchTerrainGrid)
// whose p95 on those points is at or below the adaptive volume's, within the 4096-probe
// terrain-grid limit that every bake enforces; where none is, the densest grid stands for it and
// the ratios are lower bounds ("> ...").
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
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
constexpr double kTargets[] = {0.20, 0.15, 0.10};

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
    doc["bake"]["quality"] = "draft";
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
    BakeLighting lighting = lightingOf(project);
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
    for (const double target : kTargets) {
        Project ap = base, tp = base;
        ap.scene.probeVolumes[0].placement = ProbePlacement::Adaptive;
        ap.scene.probeVolumes[0].targetError = target;
        tp.scene.probeVolumes[0].targetError = target;
        const Baked a = bake(std::move(ap), c);
        const Baked t = bake(std::move(tp), c);
        const std::string gridValue = t.volume["target"]["value"].get<std::string>();
        const std::array<int, 3> chosen{std::stoi(gridValue), 1, std::stoi(gridValue.substr(gridValue.find(',') + 1))};
        const PlacementSearch s = searchTerrainGrid(hf, a.p95, kMaxTerrainGridProbes, std::max(chosen[0], chosen[2]),
                                                    [&](const std::array<int, 3>& dims) {
                                                        const Baked& u = uniformBake(dims);
                                                        PlacementTrial trial;
                                                        trial.dims = dims;
                                                        trial.probes = u.probes;
                                                        trial.bytes = u.bytes;
                                                        trial.p95 = u.p95;
                                                        return trial;
                                                    });
        const Baked& u = uniform.at(s.chosen.dims);
        const nlohmann::json& at = a.volume["target"];
        const char* bound = s.met ? "" : "> ";
        std::printf("| %s | %.1f %% | %.0f %% | %s | %zu | %llu | %.1f | %.1f %% | %s | %zu | %.1f %% | %s | %s | %zu%s | %llu | "
                    "%.1f | %.1f %% | %s%.2f | %s%.2f |\n",
                    dem.name.c_str(), 100.0 * c.floor, 100.0 * target, at["value"].get<std::string>().c_str(), a.probes,
                    (unsigned long long)a.bytes, a.seconds, 100.0 * a.p95,
                    at["met"].get<bool>() ? "met" : "missed", t.probes, 100.0 * t.p95,
                    t.volume["target"]["capped"].get<bool>() ? "capped" : t.volume["target"]["met"].get<bool>() ? "met" : "missed",
                    dimsOf(s.chosen.dims).c_str(), u.probes,
                    !s.met ? " (misses it)" : "", (unsigned long long)u.bytes, u.seconds, 100.0 * u.p95, bound,
                    double(u.probes) / double(a.probes), bound, double(u.bytes) / double(a.bytes));
        std::fflush(stdout);
        if (a.uncovered + t.uncovered + u.uncovered > 0)
            std::fprintf(stderr, "%s %.0f %%: uncovered points: adaptive %zu, terrain %zu, uniform %zu\n",
                         dem.name.c_str(), 100.0 * target, a.uncovered, t.uncovered, u.uncovered);
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
    std::printf("Draft quality, %d threads; p95 of the relative irradiance error at %d x %d points %.0f m above the "
                "ground, each .shprobe interpolated as the engine reads it against a probe baked there at %d rays. "
                "Uniform: the coarsest terrain grid at or below the adaptive p95 within the %d-probe terrain-grid "
                "limit; where none is, the densest grid, and the ratios are lower bounds. Floor: the p95 of a draft probe baked at each point itself. "
                "Times: the whole bake, target search included.\n\n",
                kThreads, kPointsPerSide, kPointsPerSide, double(kHeight), kTruthRays, kMaxTerrainGridProbes);
    std::printf("| DEM | floor p95 | target | adaptive tolerance | probes | bytes | bake s | p95 | bake's map | terrain target "
                "probes | p95 | terrain target | uniform grid | probes | bytes | bake s | p95 | uniform / adaptive "
                "probes | uniform / adaptive bytes |\n");
    std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---|---|---:|---:|---:|---:|---:|---:|\n");
    std::fflush(stdout);
    for (const Dem& d : dems) benchDem(d, out);
    std::filesystem::remove_all(out);
    return 0;
}
