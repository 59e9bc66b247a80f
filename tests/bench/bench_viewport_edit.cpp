// How soon an edit shows in the live viewport of the authoring window, as a user sees it: the
// edit goes through the project document (as a dock's field does), and the time runs until the
// window presents the first frame recorded after it. Edits that change only the frame's uniforms
// (sun, sky, exposure, fog, water look) are the ones the window must answer at once; the sun and
// the sky also start a draft preview bake on a worker, whose light lands later and is not waited
// for here (bench_live_edit times it). Between edits the viewport is left to settle: the preview
// landed, the full-resolution frame drawn, nothing asked for.
//
// Counters: `first_ms`, edit to the first frame on screen (the dynamic resolution's scale while
// the view changes), the mean and the `worst_ms` of the edits; `scale`, that frame's side over the viewport's; `full_ms`, edit to the
// full-resolution frame that follows when the changes stop (ViewportWindow::kRefineDelayMs after
// them); `edit_ms`, the edit itself on the UI thread (the renderer takes the new project).
// Needs a display (run under xvfb-run) and a Vulkan device that can present.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include <QApplication>
#include <QElapsedTimer>
#include <QEventLoop>
#include <QTimer>

#include <benchmark/benchmark.h>

#include "MainWindow.h"
#include "ViewportWindow.h"
#include "vk/VulkanContext.h"

using namespace terralux;
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// Runs the event loop for `ms`.
void spin(int ms) {
    QEventLoop loop;
    QTimer::singleShot(ms, &loop, &QEventLoop::quit);
    loop.exec();
}

// Runs the event loop until `done` holds or `ms` pass; whether it held.
template <class F>
bool spinUntil(F done, int ms) {
    QElapsedTimer clock;
    clock.start();
    while (!done()) {
        if (clock.elapsed() > ms) return false;
        spin(5);
    }
    return true;
}

struct Window {
    std::unique_ptr<MainWindow> w;
    std::string error;
};

// The viewport has gone `quietMs` without presenting a frame, with none submitted, asked for or
// due, and no preview under way or due.
bool settle(MainWindow& w, int quietMs = 600) {
    ViewportWindow* v = w.viewport();
    auto last = Clock::now();
    auto conn = QObject::connect(v, &ViewportWindow::frameRendered, [&](double) { last = Clock::now(); });
    const bool ok = spinUntil([&] { return !v->drawing() && msSince(last) > quietMs; }, 60000);
    QObject::disconnect(conn);
    return ok;
}

// The windows, closed before the application goes (main).
std::map<int, Window>& windows() {
    static std::map<int, Window> all;
    return all;
}

Window& window(int dem) {
    auto [it, fresh] = windows().try_emplace(dem);
    Window& s = it->second;
    if (!fresh) return s;
    if (QGuiApplication::platformName() == "offscreen" || QGuiApplication::platformName() == "minimal") {
        s.error = "no display (run under xvfb-run)";
        return s;
    }
    const fs::path demFile = fs::path(TERRALUX_SHARED_DATA) / "dem" / "N42E001.hgt";
    if (dem && !fs::exists(demFile)) {
        s.error = "shared DEM N42E001.hgt not present";
        return s;
    }
    try {
        s.w = std::make_unique<MainWindow>();
    } catch (const std::exception& e) {
        s.error = e.what();
        return s;
    }
    s.w->resize(1280, 800);
    s.w->show();
    if (dem && !s.w->importDemFile(QString::fromStdString(demFile.string()))) {
        s.error = "N42E001.hgt did not import";
        return s;
    }
    // Every look the edits below change is on: fog, water with its planar reflection, the manual
    // exposure the exposure edit moves.
    QString error;
    for (const auto& [path, value] : std::map<std::string, nlohmann::json>{
             {"fog.enabled", true}, {"water.enabled", true}, {"camera.exposure_mode", "manual"}})
        if (!s.w->document()->setParameter(path, value, &error)) s.error = path + ": " + error.toStdString();
    if (!spinUntil([&] { return s.w->probeSource() == "draft preview"; }, 60000)) s.error = "no draft preview";
    settle(*s.w);
    return s;
}

struct EditCase {
    const char* label;
    const char* path;
    double a, b;  // the values the edit alternates between
};
const EditCase kEdits[] = {
    {"sun elevation", "sun.elevation_deg", 33.0, 37.0}, {"sky intensity", "sky.intensity", 1.2, 1.0},
    {"exposure", "camera.exposure_ev", 0.5, 0.0},       {"fog density", "fog.density", 4e-5, 2e-5},
    {"water roughness", "water.roughness", 0.3, 0.05},
};

void BM_ViewportEdit(benchmark::State& state) {
    const int dem = int(state.range(0));
    const EditCase& edit = kEdits[state.range(1)];
    Window& s = window(dem);
    if (!s.w || !s.error.empty()) {
        state.SkipWithError(s.error.c_str());
        return;
    }
    MainWindow& w = *s.w;
    ViewportWindow* v = w.viewport();
    double first = 0, worst = 0, full = 0, scale = 0, editMs = 0;
    int n = 0;
    for (auto _ : state) {
        if (!settle(w)) {
            state.SkipWithError("the viewport did not settle");
            return;
        }
        ++n;
        std::optional<double> firstAt, fullAt;
        double firstScale = 0;
        const auto t0 = Clock::now();
        auto conn = QObject::connect(v, &ViewportWindow::frameRendered, [&](double ms) {
            // A frame recorded before the edit does not show it.
            if (msSince(t0) - ms < 0.0) return;
            const double at = msSince(t0);
            if (!firstAt) {
                firstAt = at;
                firstScale = v->presentedScale();
            }
            if (v->presentedScale() >= 1.0 && !fullAt) fullAt = at;
        });
        QString error;
        if (!w.document()->setParameter(edit.path, n % 2 ? edit.a : edit.b, &error)) {
            QObject::disconnect(conn);
            state.SkipWithError(error.toStdString().c_str());
            return;
        }
        editMs += msSince(t0);
        const bool shown = spinUntil([&] { return fullAt.has_value(); }, 30000);
        QObject::disconnect(conn);
        if (!shown) {
            state.SkipWithError("no full-resolution frame within 30 s of the edit");
            return;
        }
        first += *firstAt;
        worst = std::max(worst, *firstAt);
        full += *fullAt;
        scale += firstScale;
        state.SetIterationTime(*firstAt / 1000.0);
    }
    state.SetLabel(std::string(edit.label) + (dem ? ", N42E001" : ", sample") + ", " +
                   std::to_string(v->width()) + " x " + std::to_string(v->height()));
    state.counters["first_ms"] = first / n;
    state.counters["worst_ms"] = worst;
    state.counters["scale"] = scale / n;
    state.counters["full_ms"] = full / n;
    state.counters["edit_ms"] = editMs / n;
}

}  // namespace

int main(int argc, char** argv) {
    qputenv("TERRALUX_AUTOSAVE_DIR", QByteArray::fromStdString((fs::temp_directory_path() / "terralux_bench_autosave").string()));
    QApplication app(argc, argv);
    benchmark::Initialize(&argc, argv);
    for (int dem : {0, 1})
        for (int e = 0; e < int(std::size(kEdits)); ++e)
            benchmark::RegisterBenchmark("BM_ViewportEdit", BM_ViewportEdit)
                ->Args({dem, e})
                ->Iterations(6)
                ->UseManualTime()
                ->Unit(benchmark::kMillisecond);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    windows().clear();
    return 0;
}
