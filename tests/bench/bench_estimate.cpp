// The dry run's time estimate against the bake it estimates (docs/lighting.md, "Dry run"): for the
// default project on every committed DEM crop, the embedded sample and, when the shared data is
// present, every shared DEM at its own resolution, `estimateBake` and then `runBake` (the same
// request, kThreads threads), the ratio of the bake's wall time to the estimate. Exits 1 when a
// ratio is outside [1 / kWithin, kWithin]: the figure a user plans with must hold.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "BakeJob.h"
#include "Project.h"

using namespace terralux;

namespace {

constexpr int kThreads = 2;
constexpr double kWithin = 1.3;

struct Dem {
    std::string name;
    std::string file;  // empty: the embedded sample
};

}  // namespace

int main() {
    const std::filesystem::path crops = std::filesystem::path(TERRALUX_TEST_DATA) / "dem";
    const std::filesystem::path shared = std::filesystem::path(TERRALUX_SHARED_DATA) / "dem";
    std::vector<Dem> dems = {{"embedded sample", ""},
                             {"bigtujunga_utm11_crop.tif", (crops / "bigtujunga_utm11_crop.tif").string()},
                             {"rainier_crop.tif", (crops / "rainier_crop.tif").string()},
                             {"orkhon_crop.asc", (crops / "orkhon_crop.asc").string()}};
    for (const char* f : {"N42E001.hgt", "mt_rainier_90m.tif", "srtm_bigtujunga30m_utm11.tif", "topotoolbox_exampleDEM.asc"})
        if (std::filesystem::exists(shared / f)) dems.push_back({f, (shared / f).string()});
    const std::filesystem::path out = std::filesystem::temp_directory_path() / "terralux_bench_estimate";
    std::printf("Default project, standard preset, %d threads; estimate: terralux --bake --dry-run; bake: the wall "
                "time of runBake, writing included.\n\n",
                kThreads);
    std::printf("| DEM | estimate s | of which loading | writing | suggestion | bake s | bake / estimate |\n");
    std::printf("|---|---:|---:|---:|---:|---:|---:|\n");
    int failures = 0;
    for (const Dem& d : dems) {
        BakeRequest request;
        request.project.scene = sceneFromJson(defaultProjectJson(), "bench", nullptr);
        request.project.scene.terrain.dem = d.file;
        request.project.scene.exportSettings.outDir = out.string();
        request.threads = kThreads;
        const BakeEstimate e = estimateBake(request);
        const auto start = std::chrono::steady_clock::now();
        runBake(request, {}, nullptr);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const double ratio = seconds / e.seconds;
        const bool ok = ratio <= kWithin && ratio >= 1.0 / kWithin;
        failures += !ok;
        std::printf("| %s | %.2f | %.2f | %.2f | %s | %.2f | %.2f%s |\n", d.name.c_str(), e.seconds, e.loadSeconds,
                    e.writeSeconds, e.volumes.empty() || !e.volumes[0].suggestionLikely ? "no" : "yes", seconds, ratio,
                    ok ? "" : " (outside)");
        std::fflush(stdout);
    }
    std::filesystem::remove_all(out);
    return failures ? 1 : 0;
}
