#include "CommandLine.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>

#include <filesystem>
#include <vector>

#include "AtomicFile.h"
#include "BakeJob.h"
#include "CommandLineHelp.h"
#include "CommandLineSupport.h"
#include "ImageFile.h"
#include "scene/DebugViews.h"
#include "DemImport.h"
#include "EnvironmentImage.h"
#include "ShProbeFile.h"
#include "bake/DiffuseBake.h"
#include "bake/ProbePlacement.h"
#include "ParameterTable.h"
#include "Project.h"
#include "SampleTerrain.h"
#include "TerrainLoading.h"
#include "TileMerge.h"
#include "Tiling.h"

#ifndef TERRALUX_VERSION
#define TERRALUX_VERSION "0.0.0"
#endif

namespace terralux {
namespace {

using namespace cli;

int commandInfo(const Args& a) {
    const QStringList positional = a.parser.positionalArguments();
    if (positional.size() > 1) throw UsageError("--info takes one FILE");
    DemImportResult r;
    if (positional.isEmpty())
        r = importDemFromMemory(kSampleTerrainName, sampleTerrainBytes(), sampleTerrainSize());
    else
        r = importDem(str(positional[0]));
    const Heightfield& hf = r.heightfield;
    const DemSourceInfo& s = r.source;
    for (const auto& w : s.warnings) std::cerr << programName() << ": warning: " << s.path << ": " << w << "\n";

    const size_t cells = size_t(hf.width()) * hf.depth();
    double sum = 0.0;
    for (float h : hf.heights()) sum += h;
    std::ostringstream o;
    o << "file:         " << s.path << "\n";
    o << "driver:       " << s.driver << "\n";
    o << "raster:       " << s.sourceWidth << " x " << s.sourceHeight << " (band 1)\n";
    o << "source crs:   "
      << (s.sourceCrs.empty() ? std::string("none (taken as metres)") : s.sourceCrs)
      << (s.sourceEpsg ? " (EPSG:" + std::to_string(s.sourceEpsg) + ")" : std::string()) << "\n";
    o << "source pixel: " << s.sourcePixelX << " x " << std::abs(s.sourcePixelY)
      << " " << s.sourcePixelUnit << "\n";
    if (s.reprojected)
        o << "reprojected:  " << hf.geo.crsName << " (EPSG:" << hf.geo.epsg << "), bilinear\n";
    o << "grid:         " << hf.width() << " x " << hf.depth() << " vertices"
      << (s.resampled ? " (area-averaged to the maximum resolution)" : "") << "\n";
    o << "pixel size:   " << fixed(hf.cellSizeX(), 3) << " x " << fixed(hf.cellSizeZ(), 3) << " m\n";
    o << "height:       " << fixed(hf.minHeight(), 2) << " .. " << fixed(hf.maxHeight(), 2)
      << " m (mean " << fixed(sum / double(cells), 2) << ", relief "
      << fixed(hf.maxHeight() - hf.minHeight(), 2) << ")\n";
    o << "nodata:       " << hf.nodataCount() << " of " << cells << " cells ("
      << fixed(100.0 * double(hf.nodataCount()) / double(cells), 3) << " %)"
      << (hf.nodataCount() ? ", filled by the membrane (Laplace) surface" : "") << "\n";
    o << "extent:       x " << fixed(hf.minX(), 2) << " .. " << fixed(hf.maxX(), 2) << " m, z "
      << fixed(hf.minZ(), 2) << " .. " << fixed(hf.maxZ(), 2) << " m ("
      << fixed((hf.maxX() - hf.minX()) / 1000.0, 3) << " x "
      << fixed((hf.maxZ() - hf.minZ()) / 1000.0, 3) << " km; north is -z)\n";
    o << "origin:       easting " << fixed(hf.geo.easting, 3) << ", northing "
      << fixed(hf.geo.northing, 3) << " (footprint centre, engine x = z = 0)\n";
    if (hf.geo.located())
        o << "on earth:     latitude " << fixed(hf.geo.latitudeDeg, 6) << ", longitude " << fixed(hf.geo.longitudeDeg, 6)
          << " (WGS 84); grid north is " << fixed(std::abs(hf.geo.gridConvergenceDeg), 3) << "° "
          << (hf.geo.gridConvergenceDeg < 0.0 ? "west" : "east") << " of true north\n";
    std::cout << o.str();
    return kExitOk;
}

int printEstimate(const BakeEstimate& e) {
    std::cout << "dry run: nothing baked, nothing written (" << e.quality << ", " << e.raysText;
    if (e.meanRays > e.rays) std::cout << ", about " << std::lround(e.meanRays) << " on the probes sampled";
    std::cout << ", " << e.bounces << (e.bounces == 1 ? " bounce, " : " bounces, ") << e.threads << " threads)\n";
    if (e.sampling) {
        const SamplingChoice& t = *e.sampling;
        std::cout << "  bake.target_error " << fixed(100.0 * t.target, 1) << " %: " << t.summary << " on "
                  << t.pilotProbes << " probes (replaces " << t.replaced << "; "
                  << (t.met ? "meets it" : "misses it") << "; "
                  << t.raySearch.trials.size() + t.bounceSearch.trials.size() << " trials, " << duration(t.seconds)
                  << ")\n";
    }
    for (const VolumeEstimate& v : e.volumes) {
        std::cout << "  " << v.name << ": ";
        if (v.placement == ProbePlacement::Adaptive)
            std::cout << "adaptive, cells " << fixed(v.minCell, 2) << " to " << fixed(v.maxCell, 2)
                      << " m, ";
        else if (v.placement == ProbePlacement::Surface)
            std::cout << "surface quadtree, squares " << fixed(v.minCell, 2) << " to " << fixed(v.maxCell, 2)
                      << " m, ";
        else
            std::cout << (v.placement == ProbePlacement::Box ? "box" : "terrain") << " grid, ";
        std::cout << v.grid[0] << " x " << v.grid[1] << " x " << v.grid[2] << " cells of "
                  << fixed(v.cellSize, 2) << " m: " << v.probes << " probes";
        if (v.placement == ProbePlacement::Surface)
            std::cout << " (a uniform grid of the smallest squares would need " << v.uniformProbes << ")";
        else if (v.placement == ProbePlacement::Adaptive)
            std::cout << " (" << v.moved << " moved up, " << v.borrowed
                      << " cells borrow the probe above; a uniform grid would need "
                      << v.uniformProbes << ")";
        else if (v.borrowed)
            std::cout << " (" << v.borrowed << " cells borrow the probe above)";
        std::cout << ", " << v.bytes << " bytes";
        if (v.errorMapPoints) std::cout << ", " << v.errorMapPoints << " error-map points";
        std::cout << ", about " << duration(v.seconds) << "\n";
        if (v.target) {
            const TargetChoice& t = *v.target;
            std::cout << "    target_error " << fixed(100.0 * t.target, 1) << " %: " << t.setting << " " << t.value;
            if (!t.replaced.empty()) std::cout << " (replaces " << t.replaced << ")";
            std::cout << ": " << targetSummary(t) << " on a " << t.mapResolution << "-point map ("
                      << (t.met ? "meets it" : "misses it") << "; " << t.trials << " trials, "
                      << duration(t.seconds) << ")\n";
        }
        if (v.plannedMap)
            std::cout << "    its error map, baked here as the bake will: mean " << fixed(100.0 * v.plannedMap->mean, 2)
                      << " % / p95 " << fixed(100.0 * v.plannedMap->p95, 2) << " %"
                      << (v.suggestionLikely ? ", high: the bake measures denser grids for a suggestion (counted above)"
                          : errorIsHigh(*v.plannedMap) ? ", high, with no denser grid within the limit to suggest"
                                                       : "")
                      << "\n";
        if (v.refines)
            std::cout << "    error-driven refinement to " << fixed(100.0 * v.tolerance, 2)
                      << " %: up to " << v.probesMax << " probes (" << v.cap << "), "
                      << v.bytesMax << " bytes, up to " << duration(v.secondsMax) << "\n";
    }
    if (e.reflection)
        std::cout << "  reflection probes: " << e.reflection->probes << " probes, " << e.reflection->bytes
                  << " bytes, about " << duration(e.reflection->seconds) << "\n";
    if (e.lpvIni)
        std::cout << "  light propagation volumes: lpv.ini (console variables) and TERRALUX_lighting.lpv\n";
    if (e.lights)
        std::cout << "  local lights: " << e.lights << " in KHR_lights_punctual\n";
    if (e.cacheSeconds > 0.0) std::cout << "  irradiance cache: about " << duration(e.cacheSeconds) << "\n";
    for (const BakeEstimate::Scenario& sc : e.scenarios)
        std::cout << "  scenario '" << sc.name << "': a cache and the probes again, about " << duration(sc.seconds)
                  << " (about " << std::lround(sc.meanRays) << " rays per probe under its light)\n";
    std::cout << "  loading the terrain, sky and albedo: " << duration(e.loadSeconds) << " (as measured here)";
    if (e.writeSeconds > 0.0) std::cout << "; writing the scene: about " << duration(e.writeSeconds);
    std::cout << "\n";
    std::cout << "estimated bake time: about " << duration(e.seconds);
    if (e.secondsMax > e.seconds) std::cout << ", up to " << duration(e.secondsMax);
    std::cout << " (" << fixed(e.probeRaysPerSecond / 1e6, 2) << " M probe rays/s measured here)\n";
    for (const auto& w : e.warnings) std::cerr << programName() << ": warning: " << w << "\n";
    return kExitOk;
}

int commandBake(const Args& a) {
    const QStringList positional = a.parser.positionalArguments();
    if (positional.size() > 1) throw UsageError("--bake takes one PROJECT");
    std::vector<std::string> warnings;
    std::vector<std::string> sets;
    if (a.parser.isSet(a.quality)) {
        // Checked here so the message names the option typed, not the parameter behind it.
        const std::string q = str(a.parser.value(a.quality));
        const ParameterSpec* spec = findParameter("bake.quality");
        if (std::find(spec->choices.begin(), spec->choices.end(), q) == spec->choices.end())
            throw UsageError("--quality " + q + ": must be " + spec->rangeText());
        sets.push_back("bake.quality=" + q);
    }
    for (const QString& s : a.parser.values(a.set)) sets.push_back(str(s));
    BakeRequest request;
    request.project = loadEffectiveProject(positional.isEmpty() ? "" : str(positional[0]), sets,
                                           a.parser.isSet(a.dem) ? str(a.parser.value(a.dem)) : "",
                                           &warnings);
    if (a.parser.isSet(a.out)) {
        const std::string dir = str(a.parser.value(a.out));
        if (dir.empty()) throw UsageError("--out: must name a folder");
        request.project.scene.exportSettings.outDir =
            std::filesystem::absolute(dir).lexically_normal().string();
    }
    for (const auto& w : warnings) std::cerr << programName() << ": warning: " << w << "\n";
    request.threads = a.parser.isSet(a.threads) ? a.parser.value(a.threads).toInt() : 0;
    request.compareReference = a.parser.isSet(a.compareReference);

    if (a.parser.isSet(a.tile) != a.parser.isSet(a.tiles))
        throw UsageError(a.parser.isSet(a.tile) ? "--tile: needs --tiles NX,NZ" : "--tiles: needs --tile I/N or IX,IZ");
    if (a.parser.isSet(a.tile)) {
        std::optional<double> halo;
        if (a.parser.isSet(a.halo)) {
            bool ok = false;
            halo = a.parser.value(a.halo).toDouble(&ok);
            if (!ok || !(std::isfinite(*halo) && *halo >= 0.0))
                throw UsageError("--halo " + str(a.parser.value(a.halo)) + ": must be a distance in metres >= 0");
        }
        try {
            request.tile = parseTiles(str(a.parser.value(a.tiles)), str(a.parser.value(a.tile)), halo);
        } catch (const std::invalid_argument& e) {
            throw UsageError(e.what());
        }
        if (a.parser.isSet(a.nearHalo)) {
            bool ok = false;
            const double near = a.parser.value(a.nearHalo).toDouble(&ok);
            if (!ok || !(std::isfinite(near) && near >= 0.0))
                throw UsageError("--near-halo " + str(a.parser.value(a.nearHalo)) + ": must be a distance in metres >= 0");
            request.tile->nearHaloMetres = near;
        }
        // Each tile in a folder of its own under the region's: what --merge reads.
        request.project.scene.exportSettings.outDir =
            (request.project.outDir() / kTilesFolder / tileName(*request.tile)).string();
        if (!a.parser.isSet(a.dryRun)) {
            if (const std::optional<std::string> why = unchangedTile(request)) {
                std::cout << tileName(*request.tile) << ": " << *why << "; skipped\n";
                return kExitOk;
            }
        }
    }

    const std::filesystem::path outDir = request.project.outDir();
    std::error_code ec;
    if (std::filesystem::exists(outDir, ec) && !std::filesystem::is_directory(outDir, ec))
        throw UsageError("--out " + outDir.string() + ": exists and is not a folder");

    if (a.parser.isSet(a.dryRun)) return printEstimate(estimateBake(request));

    // A folder that cannot be written fails now, not after the bake. One made here for nothing
    // (a failed or interrupted bake) is removed again if it stayed empty.
    const bool existed = std::filesystem::exists(outDir, ec);
    std::filesystem::create_directories(outDir, ec);
    if (ec) throw FileWriteError(outDir.string() + ": cannot create the output folder (" + ec.message() + ")");
    struct RemoveIfEmpty {
        std::filesystem::path dir;
        bool keep;
        ~RemoveIfEmpty() {
            std::error_code e;
            if (!keep && std::filesystem::is_empty(dir, e) && !e) std::filesystem::remove(dir, e);
        }
    } cleanup{outDir, existed};

    installInterruptHandlers();
    ProgressPrinter printer(a.parser.isSet(a.quiet), a.parser.value(a.progress) == "json");
    BakeOutcome outcome;
    try {
        outcome = runBake(request, std::ref(printer), &gInterrupted);
    } catch (const BakeCancelled&) {
        std::cerr << "\n" << programName() << ": interrupted; earlier outputs in " << outDir.string()
                  << " are untouched\n";
        return kExitInterrupted;
    }
    const auto& r = outcome.report;
    const auto& quality = r["quality"];
    std::cout << "baked " << r["volumes"].size() << " volume(s) in " << fixed(r["time_s"].get<double>(), 2)
              << " s (" << quality["preset"].get<std::string>() << ", ";
    if (quality["target_standard_error"].is_null())
        std::cout << quality["rays"].get<int>() << " rays";
    else
        std::cout << "each probe to " << fixed(100.0 * quality["target_standard_error"].get<double>(), 2)
                  << " % standard error in " << quality["rays"].get<int>() << " to " << quality["max_rays"].get<int>()
                  << " rays";
    const int bounces = quality["bounces"].get<int>();
    std::cout << ", " << bounces << (bounces == 1 ? " bounce, " : " bounces, ") << r["threads"].get<int>()
              << " threads)\n";
    if (r.contains("sun") && r["sun"].contains("from_sky_image")) {
        const auto& sun = r["sun"];
        if (sun["illuminance_lux"].get<double>() > 0.0)
            std::cout << "  sun: the sky image's own (sun.follow_sky) at azimuth " << fixed(sun["azimuth_deg"].get<double>(), 1)
                      << "°, elevation " << fixed(sun["elevation_deg"].get<double>(), 1) << "°, "
                      << fixed(sun["illuminance_lux"].get<double>(), 0) << " lx, radius "
                      << fixed(sun["angular_radius_deg"].get<double>(), 2) << "°: "
                      << fixed(100.0 * sun["share_of_sky"].get<double>(), 1)
                      << " % of the image's light, shadowed by the renderer, the probes keeping the rest\n";
        else
            std::cout << "  sun: the sky image has none (sun.follow_sky): it lights alone\n";
    } else if (r.contains("sun")) {
        const auto& sun = r["sun"];
        const double lat = sun["latitude_deg"].get<double>(), lon = sun["longitude_deg"].get<double>();
        const double hours = sun["time_h"].get<double>();
        const int minutes = int(std::lround(hours * 60.0));
        char clock[16];
        std::snprintf(clock, sizeof clock, "%02d:%02d", minutes / 60, minutes % 60);
        std::cout << "  sun: " << sun["date"].get<std::string>() << " " << clock << " at UTC"
                  << (sun["utc_offset_h"].get<double>() < 0.0 ? "" : "+") << fixed(sun["utc_offset_h"].get<double>(), 2)
                  << " over " << fixed(std::abs(lat), 4) << (lat < 0.0 ? "° S, " : "° N, ") << fixed(std::abs(lon), 4)
                  << (lon < 0.0 ? "° W" : "° E") << ": azimuth " << fixed(sun["azimuth_deg"].get<double>(), 1) << "° ("
                  << fixed(sun["true_azimuth_deg"].get<double>(), 1) << "° from true north), elevation "
                  << fixed(sun["elevation_deg"].get<double>(), 1) << "°\n";
    }
    if (r.contains("sampling_target")) {
        const auto& t = r["sampling_target"];
        std::cout << "  bake.target_error " << fixed(100.0 * t["target"].get<double>(), 1) << " %: "
                  << t["summary"].get<std::string>() << " (replaces " << t["replaced"].get<std::string>()
                  << "); the baked probes' p95 standard error is "
                  << fixed(100.0 * t["baked_standard_error_p95"].get<double>(), 2) << " % ("
                  << (t["met"].get<bool>() ? "meets it" : "misses it") << ")\n";
    }
    for (const auto& v : r["volumes"]) {
        std::cout << "  " << v["name"].get<std::string>() << ": " << v["probes"].get<size_t>()
                  << " probes (" << v["invalid_probes"].get<size_t>() << " inside the terrain), "
                  << v["bytes"].get<uint64_t>() << " bytes, rays per probe "
                  << v["rays_per_probe"]["min"].get<uint32_t>() << " / " << v["rays_per_probe"]["median"].get<uint32_t>()
                  << " / " << v["rays_per_probe"]["max"].get<uint32_t>() << " (min / median / max), standard error mean "
                  << fixed(100.0 * v["standard_error"]["mean"].get<double>(), 2) << " % / max "
                  << fixed(100.0 * v["standard_error"]["max"].get<double>(), 2) << " %";
        if (v.contains("reference_error") && v["reference_error"]["mean"].is_null())
            std::cout << "\n    error vs reference " << v["reference_error"]["note"].get<std::string>();
        else if (v.contains("reference_error"))
            std::cout << ", error vs reference mean "
                      << fixed(100.0 * v["reference_error"]["mean"].get<double>(), 2) << " % / p95 "
                      << fixed(100.0 * v["reference_error"]["p95"].get<double>(), 2) << " % / max "
                      << fixed(100.0 * v["reference_error"]["max"].get<double>(), 2) << " %";
        std::cout << "\n";
        if (v.contains("target")) {
            const auto& t = v["target"];
            std::cout << "    target_error " << fixed(100.0 * t["target"].get<double>(), 1) << " %: "
                      << t["setting"].get<std::string>() << " " << t["value"].get<std::string>();
            if (!t["replaced"].is_null()) std::cout << " (replaces " << t["replaced"].get<std::string>() << ")";
            std::cout << ": " << t["summary"].get<std::string>() << " ("
                      << (t["met"].get<bool>() ? "meets it" : "misses it") << ")\n";
        }
        if (v.contains("error_map") && v["error_map"]["size"][0].get<int>() == 0) {
            std::cout << "    no interpolation-error map: the volume's grid is not over the terrain\n";
        } else if (v.contains("error_map") && v["error_map"]["points"].get<int>() == 0) {
            // No data is not 0 %.
            std::cout << "    no interpolation error measured: no point of the map has a probe around it\n";
        } else if (v.contains("error_map")) {
            const auto& m = v["error_map"];
            std::cout << "    interpolation error over the ground (" << m["size"][0].get<int>() << " x "
                      << m["size"][1].get<int>() << " points, " << fixed(m["height_m"].get<double>(), 2)
                      << " m up): mean " << fixed(100.0 * m["mean"].get<double>(), 2) << " % / p95 "
                      << fixed(100.0 * m["p95"].get<double>(), 2) << " % / max "
                      << fixed(100.0 * m["max"].get<double>(), 2) << " % (debug view " << kViewInterpolationError << ")\n";
        }
        if (v.contains("suggestions") && !v["suggestions"].empty()) {
            std::cout << "    that is more than " << int(std::lround(100.0 * kSuggestAboveMeanError))
                      << " % on average or " << int(std::lround(100.0 * kSuggestAboveP95Error))
                      << " % at p95; denser probes lower it (measured on the same points):\n";
            for (const auto& s : v["suggestions"]) {
                std::cout << "     ";
                for (const auto& set : s["set"]) std::cout << " --set " << set.get<std::string>();
                std::cout << "  (" << (s.contains("tile_set") ? "this tile: " : "") << s["probes"].get<size_t>() << " probes";
                if (s["probes_max"].get<size_t>() > s["probes"].get<size_t>())
                    std::cout << ", up to " << s["probes_max"].get<size_t>();
                std::cout << ", about " << duration(s["estimated_time_s"].get<double>());
                if (s["estimated_max_time_s"].get<double>() > s["estimated_time_s"].get<double>())
                    std::cout << ", up to " << duration(s["estimated_max_time_s"].get<double>());
                const auto& e = s["predicted_error"];
                std::cout << "): mean " << fixed(100.0 * e["mean"].get<double>(), 2) << " % / p95 "
                          << fixed(100.0 * e["p95"].get<double>(), 2) << " %";
                if (!s["meets_target"].get<bool>())
                    std::cout << ", short of the " << fixed(100.0 * s["target_mean"].get<double>(), 0)
                              << " % mean aimed at";
                // A tile measured its share: the project's setting is the region's.
                if (s.contains("tile_set")) {
                    std::cout << "; the region's grid, measured on this tile as";
                    for (const auto& set : s["tile_set"]) std::cout << " " << set.get<std::string>();
                }
                std::cout << "\n";
            }
        }
    }
    if (r.contains("reflection_probes")) {
        const auto& rp = r["reflection_probes"];
        std::cout << "  reflection probes: " << rp["probes"].get<size_t>() << " (" << rp["grid"][0].get<int>() << " x "
                  << rp["grid"][1].get<int>() << "), " << rp["encoding"].get<std::string>() << ", "
                  << rp["bytes"].get<uint64_t>() << " bytes, " << rp["simvx"]["exported_ids"].size()
                  << " in the simvx records\n";
        if (rp.contains("reference_error"))
            for (const auto& e : rp["reference_error"]["by_roughness"])
                std::cout << "    error vs reference at roughness " << fixed(e["roughness"].get<double>(), 2)
                          << ": faces mean " << fixed(100.0 * e["faces"]["mean"].get<double>(), 2)
                          << " % / max " << fixed(100.0 * e["faces"]["max"].get<double>(), 2)
                          << " %, cubemap mean " << fixed(100.0 * e["cubemap"]["mean"].get<double>(), 2)
                          << " % / max " << fixed(100.0 * e["cubemap"]["max"].get<double>(), 2) << " %\n";
    }
    if (r.contains("scenarios"))
        for (const auto& sc : r["scenarios"]) {
            std::cout << "  scenario '" << sc["name"].get<std::string>() << "': " << fixed(sc["time_s"].get<double>(), 2)
                      << " s";
            for (const auto& v : sc["volumes"])
                std::cout << ", '" << v["name"].get<std::string>() << "' standard error mean "
                          << fixed(100.0 * v["standard_error"]["mean"].get<double>(), 2) << " %";
            if (sc.contains("sun") && sc["sun"].contains("from_sky_image")) {
                const auto& sun = sc["sun"];
                if (sun["illuminance_lux"].get<double>() > 0.0)
                    std::cout << ", the sky image's sun at azimuth " << fixed(sun["azimuth_deg"].get<double>(), 1)
                              << "°, elevation " << fixed(sun["elevation_deg"].get<double>(), 1) << "°, "
                              << fixed(sun["illuminance_lux"].get<double>(), 0) << " lx";
                else
                    std::cout << ", no sun in the sky image";
            }
            std::cout << "\n";
        }
    if (r.contains("lpv")) {
        const auto& lpv = r["lpv"];
        std::cout << "  light propagation volumes: " << lpv["cascades"].size() << " cascades (";
        for (size_t i = 0; i < lpv["cascades"].size(); ++i)
            std::cout << (i ? ", " : "") << fixed(lpv["cascades"][i]["size"].get<double>(), 0);
        size_t injected = 0;
        for (const auto& l : lpv["lights"]) injected += l["injected"].get<bool>() ? 1 : 0;
        std::cout << " m), " << injected << " of " << lpv["lights"].size() << " lights injected\n";
    }
    for (const auto& w : outcome.warnings) std::cerr << programName() << ": warning: " << w << "\n";
    std::cout << "wrote " << outcome.outDir.string() << ":\n";
    for (const auto& f : outcome.files)
        std::cout << "  " << f.lexically_relative(outcome.outDir).generic_string() << " ("
                  << std::filesystem::file_size(f) << " bytes)\n";
    return kExitOk;
}

int commandMerge(const Args& a) {
    if (!a.parser.positionalArguments().isEmpty())
        throw UsageError("unexpected argument '" + str(a.parser.positionalArguments()[0]) + "' (--merge takes DIR)");
    const std::string dir = str(a.parser.value(a.merge));
    if (dir.empty()) throw UsageError("--merge: must name the folder the tiles were baked into (--out)");
    const MergeOutcome m = mergeTiles(dir);
    std::cout << "merged " << m.tiles << " tiles (" << m.grids << " probe grids";
    if (m.report.contains("reflection_probes"))
        std::cout << ", " << m.report["reflection_probes"].value("probes", uint64_t(0)) << " reflection probes";
    std::cout << ") in " << m.dir.string() << ":\n";
    for (const auto& f : m.files) std::cout << "  " << f.filename().string() << "\n";
    return kExitOk;
}

int commandPrintProject(const Args& a) {
    const QStringList positional = a.parser.positionalArguments();
    if (positional.size() > 1) throw UsageError("--print-project takes one PROJECT");
    std::vector<std::string> warnings;
    std::vector<std::string> sets;
    for (const QString& s : a.parser.values(a.set)) sets.push_back(str(s));
    const Project p = loadEffectiveProject(positional.isEmpty() ? "" : str(positional[0]), sets,
                                           a.parser.isSet(a.dem) ? str(a.parser.value(a.dem)) : "",
                                           &warnings);
    for (const auto& w : warnings) std::cerr << programName() << ": warning: " << w << "\n";
    std::cout << projectToJson(p).dump(2) << "\n";
    return kExitOk;
}

}  // namespace

int runCommandLine(int argc, char** argv, Binary binary, const AuthoringCommands& authoring) {
    const CommandLineHelp help = commandLineHelp(binary);
    setProgramName(help.program);
    Args a;
    QStringList arguments;
    for (int i = 0; i < argc; ++i) arguments << QString::fromLocal8Bit(argv[i]);
    try {
        if (!a.parser.parse(arguments)) throw UsageError(str(a.parser.errorText()));
        if (a.parser.isSet(a.help)) {
            std::cout << helpText(help);
            return kExitOk;
        }
        if (a.parser.isSet(a.version)) {
            std::cout << help.program << " " << TERRALUX_VERSION << "\n";
            return kExitOk;
        }
        if (binary == Binary::Headless)
            for (const std::string& name : authoringOnlyOptions())
                if (a.parser.isSet(QString::fromStdString(name)))
                    throw UsageError("--" + name + ": not in " + help.program +
                                     ", which runs without a display or a GPU; it is a command of terralux");
        // The commands this binary has, from its help: at most one of them.
        std::vector<std::string> names;
        int commands = 0;
        for (const HelpEntry& e : help.commands) {
            const std::string name = e.syntax.substr(0, e.syntax.find_first_of(" ,"));
            if (name == "--help" || name == "--version") continue;
            names.push_back(name);
            commands += a.parser.isSet(QString::fromStdString(name.substr(2)));
        }
        if (commands > 1) {
            std::string list;
            for (size_t i = 0; i < names.size(); ++i)
                list += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
            throw UsageError("choose one command: " + list);
        }
        if (a.parser.isSet(a.threads)) {
            bool ok = false;
            const int n = a.parser.value(a.threads).toInt(&ok);
            if (!ok || n < 1 || n > 1024)
                throw UsageError("--threads " + str(a.parser.value(a.threads)) +
                                 ": must be an integer in [1, 1024]");
        }
        if (a.parser.isSet(a.dryRun) && !a.parser.isSet(a.bake))
            throw UsageError("--dry-run: only with --bake");
        for (const QCommandLineOption* o : {&a.tiles, &a.tile, &a.halo, &a.nearHalo})
            if (a.parser.isSet(*o) && !a.parser.isSet(a.bake))
                throw UsageError("--" + str(o->names().first()) + ": only with --bake");
        if (a.parser.isSet(a.halo) && !a.parser.isSet(a.tile)) throw UsageError("--halo: only with --tile");
        if (a.parser.isSet(a.nearHalo) && !a.parser.isSet(a.tile)) throw UsageError("--near-halo: only with --tile");
        if (a.parser.isSet(a.progress)) {
            const QString mode = a.parser.value(a.progress);
            if (mode != "text" && mode != "json")
                throw UsageError("--progress " + str(mode) + ": must be text or json");
            if (!a.parser.isSet(a.bake)) throw UsageError("--progress: only with --bake");
        }
        if (a.parser.isSet(a.overlay) && !a.parser.isSet(a.render))
            throw UsageError("--overlay: only with --render");
        if (a.parser.isSet(a.time) && !a.parser.isSet(a.render))
            throw UsageError("--time: only with --render");
        if (a.parser.isSet(a.profile) && !a.parser.isSet(a.render))
            throw UsageError("--profile: only with --render");
        if (a.parser.isSet(a.noRebake) && !a.parser.isSet(a.render))
            throw UsageError("--no-rebake: only with --render");
        if (a.parser.isSet(a.scenario) && !a.parser.isSet(a.render))
            throw UsageError("--scenario: only with --render");
        if (a.parser.isSet(a.quality) && !a.parser.isSet(a.bake))
            throw UsageError("--quality: only with --bake (elsewhere: --set bake.quality=PRESET)");
        if (a.parser.isSet(a.budget) && !a.parser.isSet(a.study))
            throw UsageError("--budget: only with --study");
        if (a.parser.isSet(a.device) && !a.parser.isSet(a.render) && !a.parser.isSet(a.study))
            throw UsageError("--device: only with --render or --study");
        if (a.parser.isSet(a.info)) return commandInfo(a);
        if (a.parser.isSet(a.study)) return authoring.study(a);
        if (a.parser.isSet(a.bake)) return commandBake(a);
        if (a.parser.isSet(a.merge)) return commandMerge(a);
        if (a.parser.isSet(a.render)) return authoring.render(a);
        if (a.parser.isSet(a.printProject)) return commandPrintProject(a);
        if (a.parser.isSet(a.printSchema) || a.parser.isSet(a.printReference)) {
            if (!a.parser.positionalArguments().isEmpty())
                throw UsageError("unexpected argument '" + str(a.parser.positionalArguments()[0]) + "'");
            if (a.parser.isSet(a.printSchema)) std::cout << projectSchema().dump(2) << "\n";
            else std::cout << parameterReferenceMarkdown();
            return kExitOk;
        }
        if (!a.parser.positionalArguments().isEmpty())
            throw UsageError("unexpected argument '" + str(a.parser.positionalArguments()[0]) +
                             "' (no command given)");
        std::cout << helpText(help);
        return kExitOk;
    } catch (const UsageError& e) {
        std::cerr << programName() << ": " << e.what() << "\nTry '" << programName() << " --help'.\n";
        return kExitUsage;
    } catch (const DemError& e) {
        std::cerr << programName() << ": " << e.what() << "\n";
        return kExitUsage;
    } catch (const ProjectError& e) {
        std::cerr << programName() << ": " << e.what() << "\n";
        return kExitUsage;
    } catch (const FileWriteError& e) {
        std::cerr << programName() << ": " << e.what() << "\n";
        return kExitRuntime;
    } catch (const std::filesystem::filesystem_error& e) {
        // "filesystem error: cannot create directories: ..." becomes the path and the reason.
        std::cerr << programName() << ": " << (e.path1().empty() ? std::string() : e.path1().string() + ": ")
                  << e.code().message() << "\n";
        return kExitRuntime;
    } catch (const ImageError& e) {
        std::cerr << programName() << ": " << e.what() << "\n";
        return kExitUsage;
    } catch (const PlacementError& e) {
        std::cerr << programName() << ": " << e.what() << "\n";
        return kExitUsage;
    } catch (const std::exception& e) {
        std::cerr << programName() << ": " << e.what() << "\n";
        return kExitRuntime;
    }
}

}  // namespace terralux
