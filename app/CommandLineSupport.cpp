#include "CommandLineSupport.h"

#include <cmath>

#include <nlohmann/json.hpp>

#include <csignal>
#include <cstdio>

#include <unistd.h>

namespace terralux::cli {
namespace {
std::string& programNameStorage() {
    static std::string name = "terralux";
    return name;
}
extern "C" void onInterrupt(int) { gInterrupted.store(true); }
}  // namespace

const std::string& programName() { return programNameStorage(); }
void setProgramName(std::string name) { programNameStorage() = std::move(name); }

std::string fixed(double v, int decimals) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    return buf;
}

std::string duration(double seconds) {
    if (seconds < 10.0) return fixed(seconds, 1) + " s";
    if (seconds < 600.0) return fixed(seconds, 0) + " s";
    return fixed(seconds / 60.0, 0) + " min";
}

std::atomic<bool> gInterrupted{false};

void installInterruptHandlers() {
    std::signal(SIGINT, onInterrupt);
    std::signal(SIGTERM, onInterrupt);
}

ProgressPrinter::ProgressPrinter(bool quiet, bool json) : quiet_(quiet), tty_(::isatty(2) && !json), json_(json) {}

void ProgressPrinter::operator()(const std::string& phase, double f) {
    if (quiet_) return;
    const std::lock_guard lock(mutex_);
    const int percent = int(f * 100.0);
    const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
    if (json_) {
        if (phase == phase_ && (percent == last_ || (elapsed - lastDraw_ < 0.5 && percent != 100))) return;
        last_ = percent;
        phase_ = phase;
        lastDraw_ = elapsed;
        nlohmann::json line = {{"phase", phase},
                               {"fraction", std::round(f * 1000.0) / 1000.0},
                               {"elapsed_s", std::round(elapsed * 100.0) / 100.0},
                               {"eta_s", nullptr}};
        if (f > 0.02 && f < 1.0) line["eta_s"] = std::round(elapsed * (1.0 - f) / f * 10.0) / 10.0;
        if (f >= 1.0) line["eta_s"] = 0.0;
        std::fprintf(stderr, "%s\n", line.dump().c_str());
        std::fflush(stderr);
        return;
    }
    if (!tty_ && percent / 10 == last_ / 10 && phase == phase_ && percent != 100) return;
    if (tty_ && percent == last_ && phase == phase_ && elapsed - lastDraw_ < 0.2) return;
    last_ = percent;
    phase_ = phase;
    lastDraw_ = elapsed;
    std::string eta = "";
    if (f > 0.02 && f < 1.0) eta = ", ETA " + fixed(elapsed * (1.0 - f) / f, 0) + " s";
    char line[200];
    std::snprintf(line, sizeof line, "[%3d%%] %s (%.1f s%s)", percent, phase.c_str(), elapsed, eta.c_str());
    if (tty_) std::fprintf(stderr, "\r%-78s", line);
    else std::fprintf(stderr, "%s\n", line);
    if (tty_ && percent == 100) std::fprintf(stderr, "\n");
    std::fflush(stderr);
}

}  // namespace terralux::cli
