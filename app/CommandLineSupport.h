#pragma once
// What the command-line commands share, in the headless binary and the authoring one alike: the
// parsed arguments, usage errors, number formatting, progress and interruption.

#include <QCommandLineParser>
#include <QStringList>

#include <atomic>
#include <chrono>
#include <mutex>
#include <stdexcept>
#include <string>

namespace terralux::cli {

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
    QCommandLineOption scenario{"scenario", "Lighting scenario.", "NAME[,TO,T]"};
    QCommandLineOption tiles{"tiles", "Tile cut.", "NX,NZ"};
    QCommandLineOption tile{"tile", "One tile.", "I/N|IX,IZ"};
    QCommandLineOption halo{"halo", "Halo metres.", "METRES"};
    QCommandLineOption nearHalo{"near-halo", "Near halo metres.", "METRES"};
    QCommandLineOption merge{"merge", "Merge tiles.", "DIR"};
    QCommandLineOption progress{"progress", "Progress format.", "text|json"};

    Args() {
        parser.setSingleDashWordOptionMode(QCommandLineParser::ParseAsLongOptions);
        parser.addOptions({info, printProject, printSchema, printReference, help, version, dem, set, threads, quiet, bake, out,
                           quality, compareReference, noRebake, render, size, debugView, camera, noProbes,
                           device, dryRun, overlay, time, study, budget, profile, scenario, tiles, tile, halo, nearHalo, merge, progress});
    }
};

class UsageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// "terralux" or "terralux-bake": the prefix of every message, so a farm log names the binary.
const std::string& programName();
void setProgramName(std::string name);

inline std::string str(const QString& s) { return s.toStdString(); }
std::string fixed(double v, int decimals);
// "4.2 s", "42 s", "7 min".
std::string duration(double seconds);

// Set by SIGINT and SIGTERM once a long command has installed `installInterruptHandlers`.
extern std::atomic<bool> gInterrupted;
void installInterruptHandlers();

// Percent, phase and ETA on stderr: redrawn in place on a terminal, a line per 10 % otherwise.
// `json` (--progress json, for a farm): one JSON object a line instead, at each new phase and
// each whole percent, at most two a second within a phase:
//   {"phase":"probes","fraction":0.42,"elapsed_s":3.1,"eta_s":4.3}   (eta_s null until known)
class ProgressPrinter {
public:
    explicit ProgressPrinter(bool quiet, bool json = false);
    // Called from the bake's worker threads: one at a time.
    void operator()(const std::string& phase, double f);

private:
    using Clock = std::chrono::steady_clock;
    bool quiet_, tty_, json_;
    std::mutex mutex_;
    Clock::time_point start_ = Clock::now();
    int last_ = -1;
    double lastDraw_ = 0;
    std::string phase_;
};

}  // namespace terralux::cli
