#include "BakeJob.h"

#include <algorithm>
#include <chrono>
#include <memory>
#include <numbers>
#include <cmath>
#include <thread>

#include <tbb/global_control.h>
#include <tbb/info.h>

#include "AtomicFile.h"
#include "EnvironmentImage.h"
#include "GltfExport.h"
#include "ShProbeFile.h"
#include "TerrainLoading.h"
#include "bake/DiffuseBake.h"
#include "bake/HeightfieldTracer.h"
#include "bake/ProbePlacement.h"
#include "bake/SphereSampling.h"

#ifndef TERRALUX_VERSION
#define TERRALUX_VERSION "0.0.0"
#endif

namespace terralux {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
}

nlohmann::json stats(const std::vector<float>& v) {
    if (v.empty()) return {{"mean", 0.0}, {"p95", 0.0}, {"max", 0.0}};
    std::vector<float> s = v;
    std::sort(s.begin(), s.end());
    double sum = 0;
    for (float x : s) sum += x;
    const size_t p95 = std::min(s.size() - 1, size_t(std::ceil(0.95 * double(s.size()))) - 1);
    return {{"mean", sum / double(s.size())}, {"p95", s[p95]}, {"max", s.back()}};
}

Sky loadSky(const Project& p) {
    const SkySettings& s = p.scene.sky;
    if (s.mode == SkyMode::Uniform) return Sky::uniform(s.color * float(s.intensity));
    const std::string path = p.hdrPath().string();
    RgbImage img = readEquirectImage(path);
    // The image's colour is the sky; sky.color tints it (white leaves it as it is).
    for (size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] *= s.color[int(i % 3)];
    return Sky::equirect(std::move(img.rgb), img.width, img.height, float(s.intensity),
                         float(s.rotationDeg));
}

// The .shprobe of a volume: valid probes only, occupancy pointing at their compacted indices.
ShProbeGrid toGrid(const ProbeLayout& layout, const std::vector<sh::ShRgb>& coeffs,
                   const ExportSettings& ex) {
    ShProbeGrid g;
    g.dims = glm::uvec3(layout.cellDims[0], layout.cellDims[1], layout.cellDims[2]);
    g.origin = layout.cellOrigin;
    g.spacing = layout.cellSize;
    g.defaultScale = float(ex.defaultScale);
    g.defaultAmbient = float(ex.defaultAmbient);
    std::vector<int32_t> compact(layout.positions.size(), -1);
    for (size_t i = 0; i < layout.positions.size(); ++i) {
        if (!layout.valid[i]) continue;
        compact[i] = int32_t(g.probes.size());
        ShProbeRecord r;
        r.coeffs = coeffs[i].c;
        r.scale = g.defaultScale;
        r.ambient = g.defaultAmbient;
        g.probes.push_back(r);
    }
    g.occupancy.resize(layout.cellProbe.size());
    for (size_t c = 0; c < layout.cellProbe.size(); ++c)
        g.occupancy[c] = layout.cellProbe[c] < 0 ? -1 : compact[size_t(layout.cellProbe[c])];
    return g;
}

}  // namespace

BakeOutcome runBake(const BakeRequest& request, const BakeProgress& progress,
                    const std::atomic<bool>* cancel) {
    const auto start = Clock::now();
    const Project& project = request.project;
    const SceneDescription& scene = project.scene;
    const int threads = request.threads > 0 ? request.threads : tbb::info::default_concurrency();
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));

    auto report = [&](const std::string& phase, double f) {
        if (progress) progress(phase, std::clamp(f, 0.0, 1.0));
    };
    auto cancelled = [&] { return cancel && cancel->load(); };

    report("loading terrain", 0.0);
    const DemImportResult terrain = loadProjectTerrain(project);
    const Heightfield& hf = terrain.heightfield;
    if (cancelled()) throw BakeCancelled();
    report("loading sky", 0.01);
    BakeLighting lighting;
    lighting.sky = loadSky(project);
    lighting.sun.direction = sunDirection(scene.sun.azimuthDeg, scene.sun.elevationDeg);
    lighting.sun.illuminance = scene.sun.color * float(scene.sun.illuminance);
    lighting.sun.angularRadius = float(scene.sun.angularRadiusDeg * std::numbers::pi / 180.0);
    lighting.albedo = scene.terrain.albedo;
    const HeightfieldTracer tracer(hf, HeightfieldTracer::Options{scene.terrain.skirt});
    lighting.tracer = &tracer;

    BakeQuality q = qualityPreset(scene.bake.quality);
    if (scene.bake.rays) q.rays = *scene.bake.rays;
    if (scene.bake.bounces) q.bounces = *scene.bake.bounces;
    const bool referenceMode = scene.bake.quality == QualityPreset::Reference;

    std::vector<const ProbeVolumeSettings*> volumes;
    for (const auto& v : scene.probeVolumes)
        if (v.enabled) volumes.push_back(&v);
    if (volumes.empty())
        throw ProjectError("probe_volumes: no enabled volume; enable one or add one to bake");

    std::vector<ProbeLayout> layouts;
    size_t totalProbes = 0;
    for (const auto* v : volumes) {
        layouts.push_back(placeProbes(*v, hf));
        totalProbes += layouts.back().positions.size();
    }

    // Phase weights for one progress bar: cache, probes, reference.
    const double cacheShare = (!referenceMode && q.bounces > 0) ? 0.35 : 0.0;
    const double refShare = request.compareReference && !referenceMode ? 0.45 : 0.0;
    const double probeShare = 0.97 - 0.02 - cacheShare - refShare;
    double base = 0.02;

    std::unique_ptr<IrradianceCache> cache;
    const auto cacheStart = Clock::now();
    if (!referenceMode && q.bounces > 0) {
        BakeControl c{[&](double f) { report("irradiance cache", base + cacheShare * f); }, cancel};
        cache = std::make_unique<IrradianceCache>(lighting, q.cacheResolution, q.cacheRays,
                                                  q.sunSamples, q.bounces - 1, c);
    }
    const double cacheSeconds = secondsSince(cacheStart);
    base += cacheShare;

    nlohmann::json volumeReports = nlohmann::json::array();
    std::vector<GltfProbeVolume> grids;
    uint64_t totalRays = 0;
    size_t done = 0;
    for (size_t vi = 0; vi < volumes.size(); ++vi) {
        const ProbeVolumeSettings& v = *volumes[vi];
        const ProbeLayout& layout = layouts[vi];
        const auto volumeStart = Clock::now();
        const double share = totalProbes ? double(layout.positions.size()) / double(totalProbes) : 1.0;
        const uint64_t seed = splitmix64(0x7E77A1ABull + vi);
        const int rays = v.rayCount ? *v.rayCount : q.rays;
        BakeControl c{[&](double f) {
                          report("probes '" + v.name + "'",
                                 base + probeShare * (double(done) / double(totalProbes) + share * f));
                      },
                      cancel};
        ProbeBake bake = referenceMode
                             ? referenceProbes(lighting, q.bounces, layout.positions, layout.valid,
                                               rays, seed, c)
                             : bakeProbes(lighting, cache.get(), q.bounces, layout.positions,
                                          layout.valid, rays, seed, c);
        totalRays += bake.rays;
        const double volumeSeconds = secondsSince(volumeStart);

        nlohmann::json vr = {
            {"name", v.name},
            {"placement", v.placement == ProbePlacement::Box ? "box" : "terrain"},
            {"probes", layout.validCount()},
            {"invalid_probes", layout.positions.size() - layout.validCount()},
            {"probe_grid", {layout.probeDims[0], layout.probeDims[1], layout.probeDims[2]}},
            {"rays_per_probe", rays},
            {"rays", bake.rays},
            {"time_s", volumeSeconds},
            {"fallback_blend_distance", layout.fallbackBlendDistance},
        };
        std::vector<float> se;
        for (size_t i = 0; i < layout.valid.size(); ++i)
            if (layout.valid[i]) se.push_back(bake.standardError[i]);
        vr["standard_error"] = stats(se);

        if (request.compareReference && !referenceMode) {
            BakeControl rc{[&](double f) {
                               report("reference '" + v.name + "'",
                                      base + probeShare + refShare * (double(done) / double(totalProbes) + share * f));
                           },
                           cancel};
            const int refRays = qualityPreset(QualityPreset::Reference).rays;
            const auto refStart = Clock::now();
            const ProbeBake ref = referenceProbes(lighting, q.bounces, layout.positions,
                                                  layout.valid, refRays, seed ^ 0xF00Dull, rc);
            const ErrorStats err = compareToReference(bake.sh, ref.sh, layout.valid);
            vr["reference_error"] = {{"mean", err.mean}, {"p95", err.p95}, {"max", err.max},
                                     {"reference_rays_per_probe", refRays},
                                     {"reference_path_length", q.bounces == 0 ? 0 : referencePathLength(lighting.albedo)},
                                     {"reference_time_s", secondsSince(refStart)}};
        }

        // Encoding: radiance projections, optionally windowed so irradiance is never negative,
        // or pre-convolved irradiance (Â_l L_k).
        int windowed = 0;
        float strongest = INFINITY;
        for (size_t i = 0; i < bake.sh.size(); ++i) {
            if (!layout.valid[i]) continue;
            if (scene.bake.deringing) {
                const sh::DeringResult d = sh::deringIrradiance(bake.sh[i]);
                if (d.windowed) {
                    ++windowed;
                    strongest = std::min(strongest, d.width);
                }
            }
            if (scene.bake.encoding == ShEncoding::Irradiance)
                for (int k = 0; k < sh::kCoeffCount; ++k)
                    bake.sh[i].c[size_t(k)] *= sh::kCosineLobe[size_t(sh::bandOf(k))];
        }
        if (scene.bake.deringing)
            vr["deringing"] = {{"window", "lanczos-sigma"},
                               {"probes_windowed", windowed},
                               {"strongest_width", std::isfinite(strongest) ? nlohmann::json(strongest)
                                                                            : nlohmann::json(nullptr)}};
        ShProbeGrid grid = toGrid(layout, bake.sh, scene.exportSettings);
        vr["bytes"] = grid.fileSize();
        vr["grid"] = {{"dims", {grid.dims.x, grid.dims.y, grid.dims.z}},
                      {"origin", {grid.origin.x, grid.origin.y, grid.origin.z}},
                      {"spacing", grid.spacing}};
        volumeReports.push_back(vr);
        grids.push_back({v.name, std::move(grid)});
        done += layout.positions.size();
    }
    if (cancelled()) throw BakeCancelled();

    nlohmann::json bakeInfo = {
        {"shEncoding", scene.bake.encoding == ShEncoding::Irradiance ? "irradiance" : "radiance"},
        {"shConvention", "real SH L2, k = l(l+1)+m, no Condon-Shortley phase, engine frame Y up"},
        {"qualityPreset", qualityName(scene.bake.quality)},
        {"rays", q.rays},
        {"bounces", q.bounces},
        {"deringing", scene.bake.deringing},
        {"bakeTimeSeconds", secondsSince(start)},
    };
    nlohmann::json errorEstimate = nlohmann::json::object();
    for (const auto& vr : volumeReports) {
        nlohmann::json e = {{"standardError", vr["standard_error"]}};
        if (vr.contains("reference_error")) e["referenceError"] = vr["reference_error"];
        errorEstimate[vr["name"].get<std::string>()] = e;
    }
    bakeInfo["errorEstimate"] = errorEstimate;

    report("writing", 0.97);
    BakeOutcome out;
    out.outDir = project.outDir();
    std::filesystem::create_directories(out.outDir);
    if (scene.exportSettings.gltf) {
        GltfSceneInput in;
        in.heightfield = &hf;
        in.albedo = scene.terrain.albedo;
        in.verticalScale = scene.terrain.verticalScale;
        in.volumes = grids;
        in.bake = bakeInfo;
        in.generatorVersion = TERRALUX_VERSION;
        const GltfExportResult r = exportGltfScene(out.outDir, in);
        out.files = r.files;
    } else {
        std::filesystem::create_directories(out.outDir / "sh_coeffs");
        for (const auto& g : grids) {
            const auto path = out.outDir / "sh_coeffs" / (g.name + ".shprobe");
            writeShProbeFile(path, g.grid);
            out.files.push_back(path);
        }
    }

    out.report = {
        {"generator", std::string("Terralux ") + TERRALUX_VERSION},
        {"terrain",
         {{"source", terrain.source.path},
          {"grid", {hf.width(), hf.depth()}},
          {"cell_size_m", {hf.cellSizeX(), hf.cellSizeZ()}},
          {"height_range_m", {hf.minHeight(), hf.maxHeight()}},
          {"nodata_cells", hf.nodataCount()},
          {"crs", hf.geo.crsName},
          {"epsg", hf.geo.epsg},
          {"origin", {{"easting", hf.geo.easting}, {"northing", hf.geo.northing}}}}},
        {"quality",
         {{"preset", qualityName(scene.bake.quality)},
          {"rays", q.rays},
          {"bounces", q.bounces},
          {"cache_points", cache ? size_t(cache->pointsX()) * size_t(cache->pointsZ()) : size_t(0)},
          {"cache_rays", cache ? q.cacheRays : 0},
          {"cache_time_s", cacheSeconds}}},
        {"threads", threads},
        {"rays", totalRays},
        {"time_s", secondsSince(start)},
        {"volumes", volumeReports},
    };
    nlohmann::json files = nlohmann::json::array();
    for (const auto& f : out.files) files.push_back(f.lexically_relative(out.outDir).generic_string());
    files.push_back("bake_report.json");
    out.report["files"] = files;
    const auto reportPath = out.outDir / "bake_report.json";
    writeFileAtomically(reportPath, out.report.dump(2) + "\n");
    out.files.push_back(reportPath);
    report("done", 1.0);
    return out;
}

}  // namespace terralux
