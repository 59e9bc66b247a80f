// Peak memory of the headless bake (runBake, what `terralux --bake` runs) on the largest shared
// DEM at 4096 probes, against the budget of three times the raster plus the probes. The raster
// is the imported heightfield (float32 per cell); the probes are the .shprobe bytes written.
// Each bake runs in a fresh child process, so no allocation is served from memory an earlier
// run left in the allocator, after GDAL has registered its drivers on a small committed DEM, so
// libraries' own start-up is not counted. Two peaks, each over its value just before the bake:
// "heap" is the allocator's bytes in use (glibc mallinfo2 over all arenas, sampled every
// millisecond), what the budget is about; "rss" the resident high-water mark (Linux:
// /proc/self/clear_refs resets VmHWM), which also counts library code first paged in and thread
// stacks.
// Needs the shared data beside the repository; skips when it is absent.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <fstream>
#include <string>
#include <thread>
#include <atomic>
#include <algorithm>

#include <malloc.h>

#include <sys/wait.h>
#include <unistd.h>

#include <benchmark/benchmark.h>

#include "BakeJob.h"
#include "DemImport.h"
#include "Project.h"

using namespace terralux;
namespace fs = std::filesystem;

namespace {

// One field of /proc/self/status, in bytes (0 when absent).
double statusBytes(const std::string& field) {
    std::ifstream in("/proc/self/status");
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind(field + ":", 0) == 0) return 1024.0 * std::stod(line.substr(field.size() + 1));
    }
    return 0.0;
}

bool resetPeak() {
    std::ofstream out("/proc/self/clear_refs");
    out << "5";
    return bool(out.flush());
}

double megabytes(double bytes) { return bytes / (1024.0 * 1024.0); }

double heapInUse() {
    const struct mallinfo2 m = ::mallinfo2();
    return double(m.uordblks) + double(m.hblkhd);
}

struct Measured {
    double peak = 0, heapPeak = 0, probeBytes = 0, raster = 0;
    char error[240] = {};
};

// In the child: the warm-up, the bake, and what it measured.
Measured measureBake(const fs::path& dem, bool gltf) {
    Measured m;
    const fs::path out = fs::temp_directory_path() / ("terralux_bench_bake_memory_" + std::to_string(::getpid()));
    try {
        importDem((fs::path(TERRALUX_TEST_DATA) / "dem" / "n42e001_voids_crop.tif").string());
        BakeRequest request;
        request.project.scene.terrain.dem = dem.string();
        request.project.scene.probeVolumes.at(0).gridDims = {64, 1, 64};
        request.project.scene.bake.quality = QualityPreset::Draft;
        request.project.scene.exportSettings.gltf = gltf;
        request.project.scene.exportSettings.outDir = out.string();
        request.threads = 2;
        if (!resetPeak()) throw std::runtime_error("/proc/self/clear_refs cannot reset the peak");
        const double before = statusBytes("VmRSS");
        const double heapBefore = heapInUse();
        std::atomic<bool> done{false};
        double heapPeak = heapBefore;
        std::thread sampler([&] {
            while (!done.load()) {
                heapPeak = std::max(heapPeak, heapInUse());
                std::this_thread::sleep_for(std::chrono::milliseconds(1));
            }
        });
        BakeOutcome outcome;
        try {
            outcome = runBake(request, {}, nullptr);
        } catch (...) {
            done = true;
            sampler.join();
            throw;
        }
        done = true;
        sampler.join();
        m.peak = statusBytes("VmHWM") - before;
        m.heapPeak = heapPeak - heapBefore;
        for (const fs::path& f : outcome.files)
            if (f.extension() == ".shprobe") m.probeBytes += double(fs::file_size(f));
        const DemImportResult imported = importDem(dem.string());
        m.raster = 4.0 * imported.heightfield.width() * imported.heightfield.depth();
    } catch (const std::exception& e) {
        std::snprintf(m.error, sizeof m.error, "%s", e.what());
    }
    std::error_code ec;
    fs::remove_all(out, ec);
    return m;
}

// state.range(0): 1 with the glTF scene, 0 without.
void BM_BakePeakMemory(benchmark::State& state) {
    const fs::path dem = fs::path(TERRALUX_SHARED_DATA) / "dem" / "N42E001.hgt";
    if (!fs::exists(dem)) {
        state.SkipWithError("shared DEM N42E001.hgt not present");
        return;
    }
    Measured m;
    for (auto _ : state) {
        int fds[2];
        if (::pipe(fds) != 0) {
            state.SkipWithError("pipe failed");
            return;
        }
        const pid_t child = ::fork();
        if (child == 0) {
            ::close(fds[0]);
            const Measured r = measureBake(dem, state.range(0) != 0);
            const bool sent = ::write(fds[1], &r, sizeof r) == ssize_t(sizeof r);
            ::_exit(sent ? 0 : 1);
        }
        ::close(fds[1]);
        const bool received = child > 0 && ::read(fds[0], &m, sizeof m) == ssize_t(sizeof m);
        ::close(fds[0]);
        int status = 0;
        if (child > 0) ::waitpid(child, &status, 0);
        if (!received) {
            state.SkipWithError("the measuring child process failed");
            return;
        }
    }
    if (m.error[0]) {
        state.SkipWithError(m.error);
        return;
    }
    const double budget = 3.0 * m.raster + m.probeBytes;
    state.SetLabel(state.range(0) ? "with glTF" : "probes only");
    state.counters["raster_MB"] = megabytes(m.raster);
    state.counters["probes_MB"] = megabytes(m.probeBytes);
    state.counters["heap_MB"] = megabytes(m.heapPeak);
    state.counters["rss_MB"] = megabytes(m.peak);
    state.counters["budget_MB"] = megabytes(budget);
    state.counters["heap_per_budget"] = m.heapPeak / budget;
}
BENCHMARK(BM_BakePeakMemory)->Arg(0)->Arg(1)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
