// How long an edit in the authoring window takes to reach the viewport, per kind of edit, on the
// embedded sample and on the shared N42E001 tile (1201^2), with a uniform and an HDR sky. The
// steps are the window's: the renderer takes the new project on the UI thread (`ui_ms`), the
// draft preview re-bakes the probes on a worker (`preview_ms`, only for edits that change them),
// then one frame is drawn (`frame_ms`, 1280 x 720, read back, so an upper bound of a viewport
// frame). `total_ms` is their sum: what the user waits for, besides the window's 150 ms debounce
// before a preview starts. A volume drag is one step of a drag of the probe volume's move handle
// in the viewport: the handle's edit computed and validated through the project file's rules and
// the bounds drawn again (`ui_ms`), then as any edit of the probes. The frame's GPU time (`gpu_ms`,
// and per pass, where the device writes timestamps) and host recording time (`host_ms`) beside.
#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include <benchmark/benchmark.h>

#include "FrameCost.h"
#include "PreviewBake.h"
#include "ProjectRenderer.h"
#include "TerrainLoading.h"
#include "VolumeHandles.h"

using namespace terralux;
namespace fs = std::filesystem;

namespace {

enum Edit { kSunEdit, kSkyEdit, kViewEdit, kVolumeDrag };

struct Scene {
    std::unique_ptr<vk::VulkanContext> ctx;
    std::unique_ptr<ProjectRenderer> renderer;
    Project project;
    std::string error;
};

std::unique_ptr<vk::VulkanContext>& context(std::string& error) {
    static std::string failure;
    static std::unique_ptr<vk::VulkanContext> ctx = [] {
        try {
            return std::make_unique<vk::VulkanContext>();
        } catch (const std::exception& e) {
            failure = e.what();
            return std::unique_ptr<vk::VulkanContext>();
        }
    }();
    error = failure;
    return ctx;
}

Scene& scene(int dem, int hdr) {
    static std::map<int, Scene> scenes;
    auto [it, fresh] = scenes.try_emplace(dem * 2 + hdr);
    Scene& s = it->second;
    if (!fresh) return s;
    const fs::path shared = TERRALUX_SHARED_DATA;
    const fs::path demFile = dem ? shared / "dem" / "N42E001.hgt" : fs::path();
    const fs::path sky = shared / "hdri" / "kloppenheim_06_puresky_1k.hdr";
    if (dem && !fs::exists(demFile)) {
        s.error = "shared DEM N42E001.hgt not present";
        return s;
    }
    if (hdr && !fs::exists(sky)) {
        s.error = "shared HDR sky not present";
        return s;
    }
    auto& ctx = context(s.error);
    if (!ctx) return s;
    std::vector<std::string> sets{"bake.quality=draft"};
    if (hdr) sets.insert(sets.end(), {"sky.mode=hdr", "sky.hdr=" + sky.string()});
    s.project = loadEffectiveProject("", sets, demFile.string(), nullptr);
    s.project.scene.exportSettings.outDir = (fs::temp_directory_path() / "terralux_bench_live_edit").string();
    s.renderer = std::make_unique<ProjectRenderer>(*ctx, s.project);
    s.renderer->setProbes(previewProbes(s.project, s.renderer->heightfield(), nullptr));
    RenderRequest warm;
    warm.width = 1280;
    warm.height = 720;
    s.renderer->render(warm);  // builds the pipelines: not an edit
    return s;
}

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

void BM_Edit(benchmark::State& state) {
    const int dem = int(state.range(0)), hdr = int(state.range(1));
    const Edit edit = Edit(state.range(2));
    Scene& s = scene(dem, hdr);
    if (!s.renderer) {
        state.SkipWithError(s.error.c_str());
        return;
    }
    RenderRequest q;
    q.width = 1280;
    q.height = 720;
    double ui = 0, preview = 0, frame = 0;
    int n = 0;
    FrameCost cost;
    for (auto _ : state) {
        ++n;
        Project& p = s.project;
        auto t = Clock::now();
        if (edit == kSunEdit) p.scene.sun.elevationDeg = n % 2 ? 30.0 : 40.0;
        if (edit == kSkyEdit) p.scene.sky.intensity = n % 2 ? 1.5 : 1.0;
        if (edit == kViewEdit) q.debugView = n % 2 ? 2 : 0;  // normal, then beauty again
        if (edit == kVolumeDrag) {
            // The move handle 200 m east, then back: the values the viewport writes, through the
            // project file's rules, and the bounds it then draws.
            const Heightfield& hf = s.renderer->heightfield();
            const VolumeBounds b = sceneBounds(p.scene, hf).front();
            const HandleEdit e = dragHandle(p.scene, hf, b, HandleRole::Move, glm::vec3(n % 2 ? 200.0f : -200.0f, 0.0f, 0.0f));
            nlohmann::json doc = sceneToJson(p.scene);
            for (const auto& [path, value] : e.values) applyOverride(doc, path + "=" + value.dump());
            p.scene = sceneFromJson(doc, "drag", nullptr);
            benchmark::DoNotOptimize(sceneBounds(p.scene, hf).size());
        }
        if (edit != kViewEdit) {
            // The window hands the edited project to the renderer; a view edit only redraws.
            s.renderer->setProject(p);
            ui += msSince(t);
            t = Clock::now();
            s.renderer->setProbes(previewProbes(p, s.renderer->heightfield(), nullptr));
            preview += msSince(t);
            t = Clock::now();
        }
        const RenderedImage img = s.renderer->render(q);
        benchmark::DoNotOptimize(img.rgba.data());
        frame += msSince(t);
        cost.add(s.renderer->renderer());
    }
    static const char* kEdits[] = {"sun elevation", "sky intensity", "debug view", "volume drag"};
    state.SetLabel(std::string(kEdits[edit]) + (dem ? ", N42E001" : ", sample") + (hdr ? ", HDR sky" : ", uniform sky"));
    state.counters["ui_ms"] = ui / n;
    state.counters["preview_ms"] = preview / n;
    state.counters["frame_ms"] = frame / n;
    state.counters["total_ms"] = (ui + preview + frame) / n;
    cost.report(state);
}

void cases(benchmark::internal::Benchmark* b) {
    for (int dem : {0, 1})
        for (int hdr : {0, 1})
            for (int edit : {kSunEdit, kSkyEdit, kViewEdit, kVolumeDrag}) b->Args({dem, hdr, edit});
}
BENCHMARK(BM_Edit)->Apply(cases)->Unit(benchmark::kMillisecond)->Iterations(4)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
