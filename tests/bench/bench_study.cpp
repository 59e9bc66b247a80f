// The speed/accuracy study's cost against its budget (app/Study.h), on the embedded sample
// (256 x 256, 30 m) and on the shared N42E001 SRTM tile (skipped with a note when absent), at
// budgets of 10, 30 and 120 s. Counters: the wall time over the budget, the settings measured and
// skipped, the reference's points and time, and the best p95 error the front reaches.
#include <chrono>
#include <filesystem>

#include <benchmark/benchmark.h>

#include "Project.h"
#include "Study.h"

using namespace terralux;

namespace {

void BM_Study(benchmark::State& state) {
    nlohmann::json doc = defaultProjectJson();
    const char* name = "sample";
    if (state.range(0) == 0) {
        const std::filesystem::path dem = std::filesystem::path(TERRALUX_SHARED_DATA) / "dem" / "N42E001.hgt";
        if (!std::filesystem::exists(dem)) {
            state.SkipWithError("shared DEM N42E001.hgt not present");
            return;
        }
        doc["terrain"]["dem"] = dem.string();
        name = "N42E001";
    }
    Project project;
    project.scene = sceneFromJson(doc, "bench", nullptr);
    StudyOptions options;
    options.budgetSeconds = double(state.range(1));
    StudyResult r;
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        r = runStudy(project, options, {}, nullptr);
        state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    double best = INFINITY;
    size_t front = 0;
    for (const StudyPoint& p : r.points)
        if (p.pareto) best = std::min(best, p.errorP95), ++front;
    state.counters["budget_s"] = options.budgetSeconds;
    state.counters["of_budget"] = r.elapsedSeconds / options.budgetSeconds;
    state.counters["measured"] = double(r.points.size());
    state.counters["skipped"] = double(r.skipped.size());
    state.counters["front"] = double(front);
    state.counters["ref_points"] = double(r.reference.points);
    state.counters["ref_s"] = r.reference.seconds;
    state.counters["best_p95_pct"] = 100.0 * best;
    state.SetLabel(name);
}

}  // namespace

BENCHMARK(BM_Study)
    ->ArgsProduct({{1, 0}, {10, 30, 120}})
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->UseManualTime();
BENCHMARK_MAIN();
