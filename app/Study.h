#pragma once
// The speed/accuracy study (`terralux --study`, the Trade-off panel): one project's bake swept
// knob by knob, each setting timed, its memory and output measured, and its error taken against
// the exact answer on the same points (docs/lighting.md, "The speed/accuracy study").
//
// Probe knobs (quality preset, rays, bounces, probe spacing or adaptive tolerance) are measured
// as a user meets them: the relative irradiance error, at fixed points over the ground, of the
// probes interpolated as an engine reads them against a path-traced reference at each point. So
// Monte Carlo noise, missing bounces and interpolation add up in one number. The error map's
// resolution is measured by how far its p95 is from the p95 of a map twice as dense; AO directions
// by the horizon AO's error against traced sky visibility; LPV quality and cascades by their
// error against the traced one-bounce sun irradiance; reflection cube size, rays and encoding by
// the prefiltered luminance's error against a reference cube twice as fine per probe; shadow
// cascades, map size and filter, on the Vulkan device, by where the shadow maps disagree with the
// sun's visibility traced at the terrain's vertices, seen from the project's camera.
//
// The study keeps to a time budget: every setting's cost is estimated from the throughput
// measured so far, the cheapest settings of every knob run first, and a setting that no longer
// fits is skipped with its estimate.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "Project.h"

namespace terralux {

// What the error of a study point measures.
enum class StudyMetric {
    Irradiance,      // interpolated probes against the path-traced reference at the study points
    ErrorMapP95,     // |p95 of the map − p95 of the map twice as dense| / the latter
    AmbientOcclusion,// mean |horizon AO − traced sky visibility| at terrain vertices
    Lpv,             // LPV irradiance against the traced one-bounce sun irradiance
    Reflection,      // prefiltered reflection luminance against a finer reference cube per probe
    Shadow,          // per screen tile, the share of terrain pixels where the shadow maps and the
                     // traced sun visibility differ by more than half
};
// Every metric, in the order the outputs explain them.
inline constexpr StudyMetric kStudyMetrics[] = {StudyMetric::Irradiance, StudyMetric::ErrorMapP95,
                                                StudyMetric::AmbientOcclusion, StudyMetric::Lpv,
                                                StudyMetric::Reflection, StudyMetric::Shadow};
const char* studyMetricName(StudyMetric m);
// One line: what the metric's error means, for the table and the plot's legend.
const char* studyMetricMeaning(StudyMetric m);

struct StudyPoint {
    std::string knob;                 // "quality", "rays", "bounces", "spacing", "tolerance", ...
    std::string label;                // "rays 128"
    std::vector<std::string> sets;    // --set assignments that make this setting from the project
    bool current = false;             // the project's own settings
    StudyMetric metric = StudyMetric::Irradiance;
    double seconds = 0.0;             // what the setting costs: the bake (or the map, AO, LPV; for
                                      // shadows the frame that draws the maps and their view)
    uint64_t peakMemoryBytes = 0;     // resident memory above what was resident when it began;
                                      // for shadows the maps' device memory
    uint64_t outputBytes = 0;         // .shprobe bytes (probe knobs)
    size_t probes = 0;
    double errorMean = 0.0, errorP95 = 0.0, errorMax = 0.0;
    size_t points = 0;                // where the error was measured
    bool pareto = false;              // on the front of time against p95 error (irradiance points)
    double estimatedSeconds = 0.0;    // what the study expected it to cost
};

struct StudySkip {
    std::string knob, label;
    std::vector<std::string> sets;
    double estimatedSeconds = 0.0;
    std::string reason;
};

struct StudyReference {
    size_t points = 0;
    int raysPerPoint = 0;
    float height = 0.0f;              // metres above the ground
    double seconds = 0.0;
};

struct StudyResult {
    std::string project;              // file name, or "" for an unsaved project / the sample
    std::string terrain;              // the DEM's source
    std::string volume;               // the probe volume the spacing knob varies
    double budgetSeconds = 0.0;
    double elapsedSeconds = 0.0;
    int threads = 0;
    StudyReference reference;
    std::vector<StudyPoint> points;   // in the order they ran; the current setting first
    std::vector<StudySkip> skipped;
    std::vector<std::string> notStudied;  // knobs of the project the study cannot measure, and why
};

struct StudyOptions {
    double budgetSeconds = 120.0;
    int threads = 0;                  // 0 = all cores
    std::string device;               // Vulkan device for the shadow sweeps (vk::ContextOptions::device)
};

inline constexpr double kMinStudyBudget = 5.0;
inline constexpr double kMaxStudyBudget = 24.0 * 3600.0;

// Phase name and progress in [0, 1] of the whole study (time spent over the budget).
using StudyProgress = std::function<void(const std::string& phase, double fraction)>;

// Throws the input errors of a bake (DemError, ImageError, ProjectError, PlacementError),
// ProjectError for a budget outside [kMinStudyBudget, kMaxStudyBudget], and BakeCancelled.
StudyResult runStudy(const Project& project, const StudyOptions& options, const StudyProgress& progress,
                     const std::atomic<bool>* cancel);

// Indices of the points on the Pareto front of (cost, error), both minimised: those no other
// point matches or beats in both with one strictly better. Sorted by cost. Points with a
// non-finite or non-positive coordinate are left out.
std::vector<size_t> paretoFront(const std::vector<double>& cost, const std::vector<double>& error);

// study.json, study.csv and the table of study.html.
nlohmann::json studyToJson(const StudyResult& r);
std::string studyCsv(const StudyResult& r);
std::string studyHtml(const StudyResult& r, const std::string& plotFile);
// The points as a table for the terminal.
std::string studySummary(const StudyResult& r);

// Writes study.json, study.csv, study.html and, through `writePlot` (the chart needs Qt's
// widgets, which this layer does not link), study.png, each atomically. Returns the files.
using StudyPlotWriter = std::function<void(const StudyResult&, const std::filesystem::path& png)>;
std::vector<std::filesystem::path> writeStudy(const StudyResult& r, const std::filesystem::path& dir,
                                              const StudyPlotWriter& writePlot);

}  // namespace terralux
