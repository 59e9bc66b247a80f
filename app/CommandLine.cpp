#include "CommandLine.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>

#include <QCommandLineParser>
#include <QStringList>

#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <mutex>

#include <unistd.h>

#include "AtomicFile.h"
#include "BakeJob.h"
#include "ImageFile.h"
#include "RenderJob.h"
#include "Study.h"
#include "render/DebugViews.h"
#include "DemImport.h"
#include "EnvironmentImage.h"
#include "ShProbeFile.h"
#include "bake/DiffuseBake.h"
#include "bake/ProbePlacement.h"
#include "ParameterTable.h"
#include "Project.h"
#include "SampleTerrain.h"
#include "TerrainLoading.h"

#ifndef TERRALUX_VERSION
#define TERRALUX_VERSION "0.0.0"
#endif

namespace terralux {
namespace {

const char* const kUsageTemplate = R"(Usage: terralux [PROJECT]              open the authoring window
       terralux COMMAND [OPTIONS]       work headless

Terrain-lighting authoring: import a DEM, bake spherical-harmonics probes, export .shprobe + glTF.

Commands:
  --bake [PROJECT]              Bake every enabled probe volume and export .shprobe files, a glTF
                                scene and bake_report.json into the output folder.
  --render [PROJECT]            Render the terrain lit by the probes of the last bake in the
                                output folder (baking first when there is none or it is stale)
                                into --out IMAGE (.png display-encoded, .exr scene-linear), on
                                the Vulkan device.
  --study [PROJECT]             Sweep the settings that trade bake time for accuracy (quality,
                                rays, bounces, probe spacing or adaptive tolerance, error-map
                                resolution, AO directions, LPV quality and cascades, reflection
                                cube size, rays and encoding; shadow cascades, map size and
                                filter on the Vulkan device), measure each against the exact
                                answer on the same points, and write study.json, study.csv,
                                study.png and study.html into --out DIR (default: "study"
                                beside the project or in the current folder).
  --info [FILE]                 Describe a DEM (GDAL raster) as Terralux imports it; no FILE:
                                the embedded sample terrain.
  --print-project [PROJECT]     Print the effective project (defaults, PROJECT, --set) as JSON.
  --print-schema                Print the JSON Schema (draft 2020-12) of the project file, for
                                editors that check a project as it is typed.
  --print-reference             Print the parameter reference (Markdown): every parameter with
                                its type, default, range, unit and meaning.
  --help, -h                    Show this help.
  --version                     Show the version.

Options:
  --dem FILE                    Use FILE as the terrain instead of the project's (or the sample).
  --out DIR | IMAGE             --bake: the output folder (default: export.out_dir, "bake" beside
                                the project or in the current folder); --study: its folder;
                                --render: the image.
  --budget SECONDS              --study: the time it may take (default 120); settings that
                                would not fit are skipped and listed with their estimate.
  --quality PRESET              draft | standard | high | reference (bake.quality).
  --compare-reference           Also run the brute-force reference and report the error of
                                every probe against it (slow).
  --size WxH                    Render size (default 1280x720).
  --debug-view N|NAME           What --render draws: {views}.
  --overlay LIST                --render: draw over the image, comma-separated: probes (probe
                                positions: gold valid, cyan moved up, red rejected), leaves
                                (adaptive octree leaves).
  --time T                      --render: seconds into the water's wave animation (default 0).
  --profile                     --render: draw the frame a second time, warm, and print what it
                                cost: each pass's GPU time from timestamps (where the device
                                writes them), the GPU total, and the host's recording and
                                read-back conversion, beside both frames' wall time.
  --camera AZ,EL[,RADIUS]       Orbit camera: azimuth (clockwise from north) and elevation in
                                degrees, radius in metres (default: the project's camera).
  --no-probes                   Render without probe lighting.
  --no-rebake                   --render: draw the bake in the output folder even when it is
                                stale (its recorded settings or input files differ from the
                                project's), saying what differs; without it such a bake is
                                baked again first.
  --device NAME                 --render, --study: the Vulkan device: cpu, gpu, or part of its
                                name (default: discrete GPU, integrated, then CPU).
  --dry-run                     With --bake: place the probes and print, per volume, the probe
                                count, the .shprobe bytes and the estimated bake time; bake and
                                write nothing.
  --set KEY.PATH=VALUE          Override a project parameter by its JSON path; repeatable.
                                Examples: --set sun.elevation_deg=12
                                          --set probe_volumes[0].grid_dims=16,16
                                          --set terrain.albedo=[0.25,0.22,0.2]
                                An unknown path is an error.
  --threads N                   Worker threads (default: all cores).
  --quiet                       No progress on stderr.

With no project and no --dem, commands use the embedded sample terrain (256 x 256 cells of a
30 m SRTM DEM of the San Gabriel Mountains).

Exit codes: 0 success, 2 bad usage or invalid input, 3 runtime failure, 130 interrupted.
)";

// The help text, with the debug views listed from their table and wrapped under their option.
std::string usage() {
    std::string text = kUsageTemplate;
    const std::string marker = "{views}";
    const size_t at = text.find(marker);
    const size_t column = at - text.rfind('\n', at) - 1;
    std::string wrapped;
    size_t width = column;
    const auto& views = debugViews();
    for (size_t i = 0; i < views.size(); ++i) {
        // "30 ndotl," stays on one line.
        const std::string entry = std::to_string(views[i].number) + " " + views[i].name + (i + 1 < views.size() ? "," : "");
        if (i > 0 && width + 1 + entry.size() > 97) {
            wrapped += "\n" + std::string(32, ' ');
            width = 32;
        } else if (i > 0) {
            wrapped += ' ';
            ++width;
        }
        wrapped += entry;
        width += entry.size();
    }
    return text.replace(at, marker.size(), wrapped);
}

struct Args {
    QCommandLineParser parser;
    QCommandLineOption info{"info", "Describe a DEM."};
    QCommandLineOption printProject{"print-project", "Print the effective project."};
    QCommandLineOption printSchema{"print-schema", "Print the project JSON Schema."};
    QCommandLineOption printReference{"print-reference", "Print the parameter reference."};
    QCommandLineOption help{QStringList{"help", "h"}, "Show help."};
    QCommandLineOption version{"version", "Show the version."};
    QCommandLineOption dem{"dem", "Terrain file.", "FILE"};
    QCommandLineOption set{"set", "Override.", "KEY=VALUE"};
    QCommandLineOption threads{"threads", "Worker threads.", "N"};
    QCommandLineOption quiet{"quiet", "No progress."};
    QCommandLineOption bake{"bake", "Bake."};
    QCommandLineOption out{"out", "Output folder.", "DIR"};
    QCommandLineOption quality{"quality", "Preset.", "PRESET"};
    QCommandLineOption compareReference{"compare-reference", "Compare with the reference."};
    QCommandLineOption noRebake{"no-rebake", "Draw a stale bake."};
    QCommandLineOption render{"render", "Render."};
    QCommandLineOption size{"size", "Size.", "WxH"};
    QCommandLineOption debugView{"debug-view", "View.", "N"};
    QCommandLineOption camera{"camera", "Camera.", "AZ,EL[,R]"};
    QCommandLineOption noProbes{"no-probes", "No probes."};
    QCommandLineOption device{"device", "Device.", "NAME"};
    QCommandLineOption dryRun{"dry-run", "Estimate the bake only."};
    QCommandLineOption overlay{"overlay", "Overlays.", "LIST"};
    QCommandLineOption time{"time", "Seconds.", "T"};
    QCommandLineOption study{"study", "Study."};
    QCommandLineOption budget{"budget", "Seconds.", "SECONDS"};
    QCommandLineOption profile{"profile", "Per-pass GPU time."};

    Args() {
        parser.setSingleDashWordOptionMode(QCommandLineParser::ParseAsLongOptions);
        parser.addOptions({info, printProject, printSchema, printReference, help, version, dem, set, threads, quiet, bake, out,
                           quality, compareReference, noRebake, render, size, debugView, camera, noProbes,
                           device, dryRun, overlay, time, study, budget, profile});
    }
};

class UsageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

std::string str(const QString& s) { return s.toStdString(); }

std::string fixed(double v, int decimals) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    return buf;
}

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
    for (const auto& w : s.warnings) std::cerr << "terralux: warning: " << s.path << ": " << w << "\n";

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
      << (hf.nodataCount() ? ", filled by inverse-distance interpolation" : "") << "\n";
    o << "extent:       x " << fixed(hf.minX(), 2) << " .. " << fixed(hf.maxX(), 2) << " m, z "
      << fixed(hf.minZ(), 2) << " .. " << fixed(hf.maxZ(), 2) << " m ("
      << fixed((hf.maxX() - hf.minX()) / 1000.0, 3) << " x "
      << fixed((hf.maxZ() - hf.minZ()) / 1000.0, 3) << " km; north is -z)\n";
    o << "origin:       easting " << fixed(hf.geo.easting, 3) << ", northing "
      << fixed(hf.geo.northing, 3) << " (footprint centre, engine x = z = 0)\n";
    std::cout << o.str();
    return kExitOk;
}

std::atomic<bool> gInterrupted{false};
extern "C" void onInterrupt(int) { gInterrupted.store(true); }

// Percent, phase and ETA on stderr: redrawn in place on a terminal, a line per 10 % otherwise.
class ProgressPrinter {
public:
    explicit ProgressPrinter(bool quiet) : quiet_(quiet), tty_(::isatty(2)) {}
    // Called from the bake's worker threads: one at a time.
    void operator()(const std::string& phase, double f) {
        if (quiet_) return;
        const std::lock_guard lock(mutex_);
        const int percent = int(f * 100.0);
        const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
        if (!tty_ && percent / 10 == last_ / 10 && phase == phase_ && percent != 100) return;
        if (tty_ && percent == last_ && phase == phase_ &&
            elapsed - lastDraw_ < 0.2)
            return;
        last_ = percent;
        phase_ = phase;
        lastDraw_ = elapsed;
        std::string eta = "";
        if (f > 0.02 && f < 1.0) eta = ", ETA " + fixed(elapsed * (1.0 - f) / f, 0) + " s";
        char line[200];
        std::snprintf(line, sizeof line, "[%3d%%] %s (%.1f s%s)", percent, phase.c_str(), elapsed,
                      eta.c_str());
        if (tty_) std::fprintf(stderr, "\r%-78s", line);
        else std::fprintf(stderr, "%s\n", line);
        if (tty_ && percent == 100) std::fprintf(stderr, "\n");
        std::fflush(stderr);
    }

private:
    using Clock = std::chrono::steady_clock;
    bool quiet_, tty_;
    std::mutex mutex_;
    Clock::time_point start_ = Clock::now();
    int last_ = -1;
    double lastDraw_ = 0;
    std::string phase_;
};

std::string duration(double seconds) {
    if (seconds < 10.0) return fixed(seconds, 1) + " s";
    if (seconds < 600.0) return fixed(seconds, 0) + " s";
    return fixed(seconds / 60.0, 0) + " min";
}

int printEstimate(const BakeEstimate& e) {
    std::cout << "dry run: nothing baked, nothing written (" << e.quality << ", " << e.rays
              << " rays, " << e.bounces << " bounces, " << e.threads << " threads)\n";
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
        else
            std::cout << (v.placement == ProbePlacement::Box ? "box" : "terrain") << " grid, ";
        std::cout << v.grid[0] << " x " << v.grid[1] << " x " << v.grid[2] << " cells of "
                  << fixed(v.cellSize, 2) << " m: " << v.probes << " probes";
        if (v.placement == ProbePlacement::Adaptive)
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
    std::cout << "estimated bake time: about " << duration(e.seconds);
    if (e.secondsMax > e.seconds) std::cout << ", up to " << duration(e.secondsMax);
    std::cout << " (" << fixed(e.probeRaysPerSecond / 1e6, 2) << " M probe rays/s measured here)\n";
    for (const auto& w : e.warnings) std::cerr << "terralux: warning: " << w << "\n";
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
    for (const auto& w : warnings) std::cerr << "terralux: warning: " << w << "\n";
    request.threads = a.parser.isSet(a.threads) ? a.parser.value(a.threads).toInt() : 0;
    request.compareReference = a.parser.isSet(a.compareReference);

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

    std::signal(SIGINT, onInterrupt);
    std::signal(SIGTERM, onInterrupt);
    ProgressPrinter printer(a.parser.isSet(a.quiet));
    BakeOutcome outcome;
    try {
        outcome = runBake(request, std::ref(printer), &gInterrupted);
    } catch (const BakeCancelled&) {
        std::cerr << "\nterralux: interrupted; earlier outputs in " << outDir.string()
                  << " are untouched\n";
        return kExitInterrupted;
    }
    const auto& r = outcome.report;
    std::cout << "baked " << r["volumes"].size() << " volume(s) in " << fixed(r["time_s"].get<double>(), 2)
              << " s (" << r["quality"]["preset"].get<std::string>() << ", "
              << r["quality"]["rays"].get<int>() << " rays, " << r["quality"]["bounces"].get<int>()
              << " bounces, " << r["threads"].get<int>() << " threads)\n";
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
                  << v["bytes"].get<uint64_t>() << " bytes, standard error mean "
                  << fixed(100.0 * v["standard_error"]["mean"].get<double>(), 2) << " %";
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
                std::cout << "  (" << s["probes"].get<size_t>() << " probes";
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
    if (r.contains("lpv")) {
        const auto& lpv = r["lpv"];
        std::cout << "  light propagation volumes: " << lpv["cascades"].size() << " cascades (";
        for (size_t i = 0; i < lpv["cascades"].size(); ++i)
            std::cout << (i ? ", " : "") << fixed(lpv["cascades"][i]["size"].get<double>(), 0);
        size_t injected = 0;
        for (const auto& l : lpv["lights"]) injected += l["injected"].get<bool>() ? 1 : 0;
        std::cout << " m), " << injected << " of " << lpv["lights"].size() << " lights injected\n";
    }
    for (const auto& w : outcome.warnings) std::cerr << "terralux: warning: " << w << "\n";
    std::cout << "wrote " << outcome.outDir.string() << ":\n";
    for (const auto& f : outcome.files)
        std::cout << "  " << f.lexically_relative(outcome.outDir).generic_string() << " ("
                  << std::filesystem::file_size(f) << " bytes)\n";
    return kExitOk;
}

int commandRender(const Args& a) {
    const QStringList positional = a.parser.positionalArguments();
    if (positional.size() > 1) throw UsageError("--render takes one PROJECT");
    if (!a.parser.isSet(a.out)) throw UsageError("--render needs --out IMAGE (.png or .exr)");
    const std::filesystem::path image = std::filesystem::absolute(str(a.parser.value(a.out)));
    const std::string ext = image.extension().string();
    if (ext != ".png" && ext != ".exr")
        throw UsageError("--out " + image.string() + ": extension must be .png or .exr");
    RenderRequest request;
    request.width = 1280;
    request.height = 720;
    if (a.parser.isSet(a.size)) {
        const std::string v = str(a.parser.value(a.size));
        unsigned w = 0, h = 0;
        char x = 0, extra = 0;
        if (std::sscanf(v.c_str(), "%u%c%u%c", &w, &x, &h, &extra) != 3 || x != 'x' || w < 1 ||
            h < 1 || w > 16384 || h > 16384)
            throw UsageError("--size " + v + ": expected WxH, each in [1, 16384]");
        request.width = w;
        request.height = h;
    }
    if (a.parser.isSet(a.debugView)) {
        const std::string v = str(a.parser.value(a.debugView));
        const auto view = findDebugView(v);
        if (!view) throw UsageError("--debug-view " + v + ": not one of " + debugViewList());
        request.debugView = view->number;
    }
    if (a.parser.isSet(a.time)) {
        bool ok = false;
        const double t = a.parser.value(a.time).toDouble(&ok);
        if (!ok || !std::isfinite(t) || t < 0.0 || t > 1.0e6)
            throw UsageError("--time " + str(a.parser.value(a.time)) + ": expected seconds, a number in [0, 1000000]");
        request.time = t;
    }
    request.probes = !a.parser.isSet(a.noProbes);
    request.linearOutput = ext == ".exr";
    for (const QString& o : a.parser.values(a.overlay))
        for (const QString& part : o.split(',')) {
            if (part == "probes")
                request.probePositions = true;
            else if (part == "leaves")
                request.leaves = true;
            else
                throw UsageError("--overlay " + str(o) + ": '" + str(part) +
                                 "' is not one of probes, leaves");
        }

    std::vector<std::string> warnings, sets;
    for (const QString& s : a.parser.values(a.set)) sets.push_back(str(s));
    if (a.parser.isSet(a.camera)) {
        const QStringList parts = a.parser.value(a.camera).split(',');
        bool ok = parts.size() == 2 || parts.size() == 3;
        double v[3] = {0, 0, 0};
        for (int i = 0; ok && i < parts.size(); ++i) v[i] = parts[i].toDouble(&ok);
        if (!ok)
            throw UsageError("--camera " + str(a.parser.value(a.camera)) +
                             ": expected AZ,EL[,RADIUS] in degrees and metres");
        sets.push_back("camera.azimuth_deg=" + std::to_string(v[0]));
        sets.push_back("camera.elevation_deg=" + std::to_string(v[1]));
        if (parts.size() == 3) sets.push_back("camera.radius=" + std::to_string(v[2]));
    }
    const Project project = loadEffectiveProject(positional.isEmpty() ? "" : str(positional[0]), sets,
                                                 a.parser.isSet(a.dem) ? str(a.parser.value(a.dem)) : "",
                                                 &warnings);
    for (const auto& w : warnings) std::cerr << "terralux: warning: " << w << "\n";

    vk::ContextOptions options;
    if (a.parser.isSet(a.device)) options.device = str(a.parser.value(a.device));
    std::unique_ptr<vk::VulkanContext> ctx;
    try {
        ctx = std::make_unique<vk::VulkanContext>(options);
    } catch (const vk::VulkanUnavailable& e) {
        std::cerr << "terralux: " << e.what() << "; --bake works without one\n";
        return kExitRuntime;
    }
    ProjectRenderer renderer(*ctx, project);
    std::string note;
    std::vector<std::string> probeWarnings;
    const size_t volumes =
        request.probes ? renderer.loadProbes(!a.parser.isSet(a.noRebake), &note, &probeWarnings) : 0;
    if (!note.empty() && !a.parser.isSet(a.quiet)) std::cerr << "terralux: " << note << "\n";
    if (request.probes && volumes == 0) {
        // --no-rebake with nothing baked: say so, rather than call a missing bake stale.
        std::cerr << "terralux: warning: " << project.outDir().string()
                  << " holds no bake to draw (--no-rebake): " << renderer.staleBake().front()
                  << "; rendering without probes\n";
    } else if (!renderer.staleBake().empty()) {
        std::cerr << "terralux: warning: " << project.outDir().string() << " holds a stale bake (--no-rebake draws it):";
        for (const auto& d : renderer.staleBake()) std::cerr << (&d == &renderer.staleBake().front() ? " " : "; ") << d;
        std::cerr << "\n";
    }
    // Only the views that need the diagnostics complain about their absence.
    if (findDebugView(request.debugView)->needs.probeDiagnostics)
        for (const auto& w : probeWarnings) std::cerr << "terralux: warning: " << w << "\n";
    if (request.debugView == kViewInterpolationError && volumes > 0 && probeWarnings.empty() &&
        !renderer.hasErrorMap())
        std::cerr << "terralux: note: this bake measured no interpolation-error map "
                     "(bake.error_map_resolution = 0, or no volume over the terrain): view "
                  << kViewInterpolationError << " is grey\n";
    const RenderedImage img = renderer.render(request);
    writeImage(image, img.width, img.height, img.rgba);
    // The first frame builds pipelines, maps and volumes; the profile is of the same frame warm.
    std::optional<RenderedImage> warm;
    if (a.parser.isSet(a.profile)) warm = renderer.render(request);
    const auto view = findDebugView(std::to_string(request.debugView));
    std::cout << "rendered " << image.string() << " (" << img.width << "x" << img.height << ", view "
              << view->number << " " << view->name << ", " << volumes << " probe volume(s), "
              << ctx->deviceName() << ", " << fixed(img.milliseconds, 1) << " ms)\n";
    if (warm) {
        const FrameTimings& t = renderer.renderer().lastFrameTimings();
        std::cout << "profile (the frame drawn again, warm):\n";
        if (t.gpuTimed()) {
            size_t width = 8;
            for (const auto& p : t.passes) width = std::max(width, p.name.size());
            std::cout << "  " << std::left << std::setw(int(width)) << "pass" << std::right << "  GPU ms\n";
            for (const auto& p : t.passes)
                std::cout << "  " << std::left << std::setw(int(width)) << p.name << std::right << std::setw(8)
                          << fixed(p.gpuMilliseconds, 3) << "\n";
            std::cout << "  " << std::left << std::setw(int(width)) << "GPU total" << std::right << std::setw(8)
                      << fixed(t.gpuMilliseconds, 3) << "\n";
        } else {
            std::cout << "  GPU: " << ctx->deviceName() << " writes no timestamps\n";
        }
        std::cout << "  host: recording " << fixed(t.recordMilliseconds, 2) << " ms, read-back conversion "
                  << fixed(t.readbackMilliseconds, 2) << " ms; wall " << fixed(warm->milliseconds, 1)
                  << " ms warm, " << fixed(img.milliseconds, 1) << " ms cold\n";
    }
    // The LPV views' own exposure, printed with the view so the image can be read as numbers.
    if (view->number == kViewLpvCascade0 || view->number == kViewLpvAll) {
        if (const std::optional<double> range = renderer.renderer().lpvViewRange())
            std::cout << "LPV view scale: E/pi / " << std::setprecision(4) << *range
                      << " W/(m2 sr) through the display curve ("
                      << (request.linearOutput ? "this EXR holds E/pi unscaled" : "1.0 shows as 0.9") << ")\n";
        else
            std::cout << "LPV view scale: the light propagation volumes hold no light here\n";
    }
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
    for (const auto& w : warnings) std::cerr << "terralux: warning: " << w << "\n";
    std::cout << projectToJson(p).dump(2) << "\n";
    return kExitOk;
}

}  // namespace

int commandStudy(const Args& a, const StudyPlotWriter& writePlot) {
    const QStringList positional = a.parser.positionalArguments();
    if (positional.size() > 1) throw UsageError("--study takes one PROJECT");
    StudyOptions options;
    if (a.parser.isSet(a.budget)) {
        bool ok = false;
        options.budgetSeconds = a.parser.value(a.budget).toDouble(&ok);
        if (!ok || !(options.budgetSeconds >= kMinStudyBudget && options.budgetSeconds <= kMaxStudyBudget))
            throw UsageError("--budget " + str(a.parser.value(a.budget)) + ": must be a number of seconds in [" +
                             fixed(kMinStudyBudget, 0) + ", " + fixed(kMaxStudyBudget, 0) + "]");
    }
    options.threads = a.parser.isSet(a.threads) ? a.parser.value(a.threads).toInt() : 0;
    if (a.parser.isSet(a.device)) options.device = str(a.parser.value(a.device));
    std::vector<std::string> sets, warnings;
    for (const QString& s : a.parser.values(a.set)) sets.push_back(str(s));
    const Project project = loadEffectiveProject(positional.isEmpty() ? "" : str(positional[0]), sets,
                                                 a.parser.isSet(a.dem) ? str(a.parser.value(a.dem)) : "", &warnings);
    for (const auto& w : warnings) std::cerr << "terralux: warning: " << w << "\n";
    std::filesystem::path outDir;
    if (a.parser.isSet(a.out)) {
        const std::string dir = str(a.parser.value(a.out));
        if (dir.empty()) throw UsageError("--out: must name a folder");
        outDir = std::filesystem::absolute(dir).lexically_normal();
    } else {
        outDir = project.resolve("study");
    }
    std::error_code ec;
    if (std::filesystem::exists(outDir, ec) && !std::filesystem::is_directory(outDir, ec))
        throw UsageError("--out " + outDir.string() + ": exists and is not a folder");

    std::signal(SIGINT, onInterrupt);
    std::signal(SIGTERM, onInterrupt);
    ProgressPrinter printer(a.parser.isSet(a.quiet));
    StudyResult result;
    try {
        result = runStudy(project, options, std::ref(printer), &gInterrupted);
    } catch (const BakeCancelled&) {
        std::cerr << "\nterralux: interrupted; nothing written\n";
        return kExitInterrupted;
    }
    const auto files = writeStudy(result, outDir, writePlot);
    std::cout << studySummary(result);
    std::cout << "wrote " << outDir.string() << ":\n";
    for (const auto& f : files) std::cout << "  " << f.filename().string() << "\n";
    return kExitOk;
}

int runCommandLine(int argc, char** argv, const StudyPlotWriter& writeStudyPlot) {
    Args a;
    QStringList arguments;
    for (int i = 0; i < argc; ++i) arguments << QString::fromLocal8Bit(argv[i]);
    try {
        if (!a.parser.parse(arguments)) throw UsageError(str(a.parser.errorText()));
        if (a.parser.isSet(a.help)) {
            std::cout << usage();
            return kExitOk;
        }
        if (a.parser.isSet(a.version)) {
            std::cout << "terralux " << TERRALUX_VERSION << "\n";
            return kExitOk;
        }
        const int commands = int(a.parser.isSet(a.info)) + int(a.parser.isSet(a.printProject)) +
                             int(a.parser.isSet(a.bake)) + int(a.parser.isSet(a.render)) +
                             int(a.parser.isSet(a.printSchema)) + int(a.parser.isSet(a.printReference)) +
                             int(a.parser.isSet(a.study));
        if (commands > 1)
            throw UsageError("choose one command: --bake, --render, --study, --info, --print-project, "
                             "--print-schema or --print-reference");
        if (a.parser.isSet(a.threads)) {
            bool ok = false;
            const int n = a.parser.value(a.threads).toInt(&ok);
            if (!ok || n < 1 || n > 1024)
                throw UsageError("--threads " + str(a.parser.value(a.threads)) +
                                 ": must be an integer in [1, 1024]");
        }
        if (a.parser.isSet(a.dryRun) && !a.parser.isSet(a.bake))
            throw UsageError("--dry-run: only with --bake");
        if (a.parser.isSet(a.overlay) && !a.parser.isSet(a.render))
            throw UsageError("--overlay: only with --render");
        if (a.parser.isSet(a.time) && !a.parser.isSet(a.render))
            throw UsageError("--time: only with --render");
        if (a.parser.isSet(a.profile) && !a.parser.isSet(a.render))
            throw UsageError("--profile: only with --render");
        if (a.parser.isSet(a.noRebake) && !a.parser.isSet(a.render))
            throw UsageError("--no-rebake: only with --render");
        if (a.parser.isSet(a.quality) && !a.parser.isSet(a.bake))
            throw UsageError("--quality: only with --bake (elsewhere: --set bake.quality=PRESET)");
        if (a.parser.isSet(a.budget) && !a.parser.isSet(a.study))
            throw UsageError("--budget: only with --study");
        if (a.parser.isSet(a.device) && !a.parser.isSet(a.render) && !a.parser.isSet(a.study))
            throw UsageError("--device: only with --render or --study");
        if (a.parser.isSet(a.info)) return commandInfo(a);
        if (a.parser.isSet(a.study)) return commandStudy(a, writeStudyPlot);
        if (a.parser.isSet(a.bake)) return commandBake(a);
        if (a.parser.isSet(a.render)) return commandRender(a);
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
        std::cout << usage();
        return kExitOk;
    } catch (const UsageError& e) {
        std::cerr << "terralux: " << e.what() << "\nTry 'terralux --help'.\n";
        return kExitUsage;
    } catch (const DemError& e) {
        std::cerr << "terralux: " << e.what() << "\n";
        return kExitUsage;
    } catch (const ProjectError& e) {
        std::cerr << "terralux: " << e.what() << "\n";
        return kExitUsage;
    } catch (const FileWriteError& e) {
        std::cerr << "terralux: " << e.what() << "\n";
        return kExitRuntime;
    } catch (const std::filesystem::filesystem_error& e) {
        // "filesystem error: cannot create directories: ..." becomes the path and the reason.
        std::cerr << "terralux: " << (e.path1().empty() ? std::string() : e.path1().string() + ": ")
                  << e.code().message() << "\n";
        return kExitRuntime;
    } catch (const vk::VulkanError& e) {
        std::cerr << "terralux: " << e.what() << "\n";
        return kExitRuntime;
    } catch (const ImageError& e) {
        std::cerr << "terralux: " << e.what() << "\n";
        return kExitUsage;
    } catch (const PlacementError& e) {
        std::cerr << "terralux: " << e.what() << "\n";
        return kExitUsage;
    } catch (const std::exception& e) {
        std::cerr << "terralux: " << e.what() << "\n";
        return kExitRuntime;
    }
}

}  // namespace terralux
