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

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <benchmark/benchmark.h>

#include <optional>

#include <gdal_priv.h>

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
    double maxRss = 0;  // the process's resident high-water mark, start-up included (getrusage)
    char error[240] = {};
};

// In the child: the warm-up, the bake, and what it measured. `tile`: bake that tile of the DEM
// (its probes scaled to it, the glTF off: a 1 m tile's mesh is its own question).
Measured measureBake(const fs::path& dem, bool gltf, const std::optional<TileSpec>& tile = std::nullopt) {
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
        request.tile = tile;
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
        struct rusage usage {};
        if (::getrusage(RUSAGE_SELF, &usage) == 0) m.maxRss = 1024.0 * double(usage.ru_maxrss);
        m.heapPeak = heapPeak - heapBefore;
        for (const fs::path& f : outcome.files)
            if (f.extension() == ".shprobe") m.probeBytes += double(fs::file_size(f));
        if (tile) {
            const auto& t = outcome.report["tile"]["traced"];
            m.raster = 4.0 * t["cols"].get<double>() * t["rows"].get<double>();
        } else {
            const DemImportResult imported = importDem(dem.string());
            m.raster = 4.0 * imported.heightfield.width() * imported.heightfield.depth();
        }
    } catch (const std::exception& e) {
        std::snprintf(m.error, sizeof m.error, "%s", e.what());
    }
    std::error_code ec;
    fs::remove_all(out, ec);
    return m;
}

// Runs `measure` in a fresh child process and receives what it measured; false (the benchmark
// skipped) when the child failed.
template <class Measure>
bool inChild(benchmark::State& state, Measured& m, const Measure& measure) {
    int fds[2];
    if (::pipe(fds) != 0) {
        state.SkipWithError("pipe failed");
        return false;
    }
    const pid_t child = ::fork();
    if (child == 0) {
        ::close(fds[0]);
        const Measured r = measure();
        const bool sent = ::write(fds[1], &r, sizeof r) == ssize_t(sizeof r);
        ::_exit(sent ? 0 : 1);
    }
    ::close(fds[1]);
    const bool received = child > 0 && ::read(fds[0], &m, sizeof m) == ssize_t(sizeof m);
    ::close(fds[0]);
    int status = 0;
    if (child > 0) ::waitpid(child, &status, 0);
    if (!received) state.SkipWithError("the measuring child process failed");
    return received;
}

// state.range(0): 1 with the glTF scene, 0 without.
void BM_BakePeakMemory(benchmark::State& state) {
    const fs::path dem = fs::path(TERRALUX_SHARED_DATA) / "dem" / "N42E001.hgt";
    if (!fs::exists(dem)) {
        state.SkipWithError("shared DEM N42E001.hgt not present");
        return;
    }
    Measured m;
    for (auto _ : state)
        if (!inChild(state, m, [&] { return measureBake(dem, state.range(0) != 0); })) return;
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

// A 20 000 x 20 000 DEM at 1 m (a lidar tile of 20 km): the committed Big Tujunga crop resampled
// (bilinear) onto that grid, written once as a tiled, deflated GeoTIFF in the temporary folder.
fs::path syntheticLidar() {
    const fs::path path = fs::temp_directory_path() / "terralux_bench_lidar_20000.tif";
    if (fs::exists(path)) return path;
    GDALAllRegister();
    GDALDataset* src = static_cast<GDALDataset*>(
        GDALOpen((fs::path(TERRALUX_TEST_DATA) / "dem" / "bigtujunga_utm11_crop.tif").c_str(), GA_ReadOnly));
    if (!src) throw std::runtime_error("cannot open the committed crop");
    double gt[6];
    src->GetGeoTransform(gt);
    const int n = 20000;
    GDALDriver* gtiff = GetGDALDriverManager()->GetDriverByName("GTiff");
    char** opts = nullptr;
    opts = CSLSetNameValue(opts, "TILED", "YES");
    opts = CSLSetNameValue(opts, "COMPRESS", "DEFLATE");
    opts = CSLSetNameValue(opts, "BIGTIFF", "YES");
    const fs::path partial = path.string() + ".part";
    GDALDataset* dst = gtiff->Create(partial.c_str(), n, n, 1, GDT_Float32, opts);
    CSLDestroy(opts);
    const double out[6] = {gt[0], 1.0, 0.0, gt[3], 0.0, -1.0};
    dst->SetGeoTransform(const_cast<double*>(out));
    dst->SetSpatialRef(src->GetSpatialRef());
    // Row bands: the crop read whole once (it is small), each output row band resampled from it.
    const int sw = src->GetRasterXSize(), sh = src->GetRasterYSize();
    std::vector<float> crop(size_t(sw) * sh);
    if (src->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, sw, sh, crop.data(), sw, sh, GDT_Float32, 0, 0, nullptr) != CE_None)
        throw std::runtime_error("cannot read the committed crop");
    std::vector<float> band(size_t(n) * 256);
    for (int y0 = 0; y0 < n; y0 += 256) {
        const int rows = std::min(256, n - y0);
        for (int y = 0; y < rows; ++y) {
            const double v = (y0 + y + 0.5) * (sh - 1) / double(n);
            const int r = std::min(int(v), sh - 2);
            const double fy = v - r;
            for (int x = 0; x < n; ++x) {
                const double u = (x + 0.5) * (sw - 1) / double(n);
                const int c = std::min(int(u), sw - 2);
                const double fx = u - c;
                auto at = [&](int cc, int rr) { return double(crop[size_t(rr) * sw + cc]); };
                band[size_t(y) * n + x] = float((1 - fy) * ((1 - fx) * at(c, r) + fx * at(c + 1, r)) +
                                                fy * ((1 - fx) * at(c, r + 1) + fx * at(c + 1, r + 1)));
            }
        }
        if (dst->GetRasterBand(1)->RasterIO(GF_Write, 0, y0, n, rows, band.data(), n, rows, GDT_Float32, 0, 0, nullptr) != CE_None)
            throw std::runtime_error("cannot write the synthetic DEM");
    }
    GDALClose(dst);
    GDALClose(src);
    fs::rename(partial, path);
    return path;
}

// One tile of a 4 x 4 cut of the 20 000² DEM, its halo state.range(0) metres (0: derived from the
// relief, about 10 km here, so the halo window is the whole DEM) and its near halo, read at the DEM's
// resolution, state.range(1) metres (0: derived from the overview's cells, about 2 km here; beyond
// it the halo is traced on the overview). Peak memory against the raster the tile reads
// (rss_per_traced) and against the whole DEM's 1.6 GB.
void BM_TilePeakMemory(benchmark::State& state) {
    fs::path dem;
    try {
        dem = syntheticLidar();
    } catch (const std::exception& e) {
        state.SkipWithError(e.what());
        return;
    }
    TileSpec tile = parseTiles("4,4", "5/16", state.range(0) > 0 ? std::optional<double>(double(state.range(0))) : std::nullopt);
    if (state.range(1) > 0) tile.nearHaloMetres = double(state.range(1));
    Measured m;
    for (auto _ : state)
        if (!inChild(state, m, [&] { return measureBake(dem, false, tile); })) return;
    if (m.error[0]) {
        state.SkipWithError(m.error);
        return;
    }
    state.SetLabel((state.range(0) ? "halo " + std::to_string(state.range(0)) + " m" : std::string("derived halo")) +
                   (state.range(1) ? ", near halo " + std::to_string(state.range(1)) + " m" : std::string(", derived near halo")));
    state.counters["traced_MB"] = megabytes(m.raster);
    state.counters["whole_MB"] = megabytes(4.0 * 20000.0 * 20000.0);
    state.counters["heap_MB"] = megabytes(m.heapPeak);
    // What a batch engine sees of the task: the whole process's high-water mark.
    state.counters["rss_MB"] = megabytes(m.maxRss);
    state.counters["rss_per_traced"] = m.maxRss / m.raster;
}
BENCHMARK(BM_TilePeakMemory)
    ->Args({500, 0})
    ->Args({2000, 0})
    ->Args({0, 0})
    ->Args({0, 5000})
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
