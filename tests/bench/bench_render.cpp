// Frame time per debug view at 1280 x 720 over a 1201^2 real DEM (the shared N42E001 tile), and
// the cost of probe lighting against none. Draw + readback, wall clock, on whatever device
// TERRALUX_VK_DEVICE picks (lavapipe here; a GPU where there is one).
//
// The shadow trade: at a low sun (10°), for 1-4 cascades, 1024-4096 maps and the three filters,
// the share of terrain pixels where the shadow map (view 31) and the traced sun visibility (view 29)
// disagree by more than 0.5, beside the frame time of beauty with those shadows; and beauty with
// shadows and fog each on and off.
#include <chrono>
#include <filesystem>
#include <map>
#include <memory>

#include <benchmark/benchmark.h>

#include "FrameCost.h"
#include "PreviewBake.h"
#include "ProjectRenderer.h"
#include "TerrainLoading.h"
#include "lpv/Lpv.h"
#include "scene/DynamicResolution.h"
#include "scene/DebugViews.h"

using namespace terralux;

namespace {

struct Fixture {
    std::unique_ptr<vk::VulkanContext> ctx;
    std::unique_ptr<ProjectRenderer> renderer;
    std::string error;
};

Project fixtureProject() {
    const auto dem = std::filesystem::path(TERRALUX_SHARED_DATA) / "dem" / "N42E001.hgt";
    // Manual exposure: a metered frame first draws its 128-pixel meter (BM_MeteredFrame times
    // that), whose passes the frame's own timings would not show.
    Project p = loadEffectiveProject("", {"bake.quality=draft", "probe_volumes[0].grid_dims=64,64",
                                          "camera.exposure_mode=\"manual\""},
                                     dem.string(), nullptr);
    p.scene.exportSettings.outDir = (std::filesystem::temp_directory_path() / "terralux_bench_render").string();
    return p;
}

Fixture& fixture() {
    static Fixture f = [] {
        Fixture x;
        const auto dem = std::filesystem::path(TERRALUX_SHARED_DATA) / "dem" / "N42E001.hgt";
        if (!std::filesystem::exists(dem)) {
            x.error = "shared DEM N42E001.hgt not present";
            return x;
        }
        try {
            x.ctx = std::make_unique<vk::VulkanContext>();
        } catch (const std::exception& e) {
            x.error = e.what();
            return x;
        }
        x.renderer = std::make_unique<ProjectRenderer>(*x.ctx, fixtureProject());
        x.renderer->loadProbes(true);
        // The first frame builds the pipelines (lavapipe compiles them then): not a frame time.
        RenderRequest warm;
        warm.width = 1280;
        warm.height = 720;
        x.renderer->render(warm);
        return x;
    }();
    return f;
}

void BM_Frame(benchmark::State& state) {
    Fixture& f = fixture();
    if (!f.renderer) {
        state.SkipWithError(f.error.c_str());
        return;
    }
    RenderRequest q;
    q.width = 1280;
    q.height = 720;
    q.debugView = int(state.range(0));
    q.probes = state.range(1) != 0;
    double ms = 0;
    FrameCost cost;
    for (auto _ : state) {
        const RenderedImage img = f.renderer->render(q);
        ms += img.milliseconds;
        cost.add(f.renderer->renderer());
        benchmark::DoNotOptimize(img.rgba.data());
    }
    const auto view = findDebugView(std::to_string(q.debugView));
    state.SetLabel(std::string(view->name) + (q.probes ? "" : " (no probes)") + " on " + f.ctx->deviceName());
    state.counters["frame_ms"] = ms / double(state.iterations());
    cost.report(state);
    state.counters["vertices"] = double(f.renderer->renderer().vertexCount());
    state.counters["stride"] = f.renderer->renderer().meshStride();
}

void views(benchmark::internal::Benchmark* b) {
    for (const auto& v : debugViews()) b->Args({v.number, 1});
    b->Args({0, 0});
}
BENCHMARK(BM_Frame)->Apply(views)->Unit(benchmark::kMillisecond)->Iterations(5)->UseRealTime();

const char* const kFilters[] = {"pcss", "pcf", "hard"};

// A renderer of the same DEM at a low sun, with the given shadow settings.
Project lowSunProject(int cascades, int resolution, int filter, bool heightfield) {
    Project p = fixtureProject();
    p.scene.sun.elevationDeg = 10.0;
    p.scene.shadows.cascades = cascades;
    p.scene.shadows.mapResolution = resolution;
    p.scene.shadows.filter = ShadowFilter(filter);
    p.scene.shadows.heightfield = heightfield;
    return p;
}

void BM_ShadowAgreement(benchmark::State& state) {
    Fixture& f = fixture();
    if (!f.renderer) {
        state.SkipWithError(f.error.c_str());
        return;
    }
    const int cascades = int(state.range(0)), resolution = int(state.range(1)), filter = int(state.range(2));
    const bool heightfield = state.range(3) != 0;
    f.renderer->setProject(lowSunProject(cascades, resolution, filter, heightfield));
    ShadowAgreement a;
    RenderRequest q;
    q.width = 1280;
    q.height = 720;
    double ms = 0;
    for (auto _ : state) {
        a = measureShadowAgreement(*f.renderer, 1280, 720);
        // Beauty with these shadows; the camera does not move, so the maps are drawn once
        // (the first frame), as in a viewport between edits: time both.
        f.renderer->setProject(lowSunProject(cascades, resolution, filter, heightfield));
        ms += f.renderer->render(q).milliseconds;
    }
    state.SetLabel(std::to_string(cascades) + " cascades, " + std::to_string(resolution) + "², " + kFilters[filter] +
                   (heightfield ? ", terrain horizon" : ", maps only"));
    state.counters["disagree_pct"] = 100.0 * a.disagreeing;
    state.counters["acne_pct"] = 100.0 * a.acne;
    state.counters["mean_abs_diff"] = a.meanAbsDifference;
    state.counters["shadow_view_ms"] = a.shadowMilliseconds;
    state.counters["beauty_ms"] = ms / double(state.iterations());
}

// The maps alone over cascades, sizes and filters; then the default with the terrain's horizon.
void shadowSettings(benchmark::internal::Benchmark* b) {
    for (int cascades : {1, 2, 4})
        for (int resolution : {1024, 2048, 4096})
            for (int filter : {0, 1, 2})
                if (filter == 0 || (cascades == 4 && resolution == 2048) || (cascades == 1 && resolution == 4096))
                    b->Args({cascades, resolution, filter, 0});
    b->Args({3, 2048, 0, 0});
    b->Args({4, 2048, 0, 1});
}
BENCHMARK(BM_ShadowAgreement)->Apply(shadowSettings)->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();

// Acne and agreement at low, middle and high suns (azimuth 135°) on the embedded sample and the
// shared mountain tiles, from the default framing (far) and from a camera a third as far at 15°
// elevation (near): the cases RenderTest.ShadowMapsHaveNoAcneAtLowMiddleAndHighSuns holds on the
// committed crops, at 1280 x 720 and the default shadow settings, and with the maps alone
// (shadows.heightfield off).
void BM_ShadowCases(benchmark::State& state) {
    Fixture& f = fixture();
    if (!f.ctx) {
        state.SkipWithError(f.error.c_str());
        return;
    }
    const char* dems[] = {"", "N42E001.hgt", "mt_rainier_90m.tif"};
    const int dem = int(state.range(0)), sun = int(state.range(1));
    const bool near = state.range(2) != 0, heightfield = state.range(3) != 0;
    const std::string path = dem == 0 ? std::string() : (std::filesystem::path(TERRALUX_SHARED_DATA) / "dem" / dems[dem]).string();
    std::vector<std::string> sets = {"bake.quality=draft", "sun.mode=\"manual\"", "sun.azimuth_deg=135",
                                     "sun.elevation_deg=" + std::to_string(sun), "camera.azimuth_deg=210"};
    if (near) sets.push_back("camera.elevation_deg=15");
    if (!heightfield) sets.push_back("shadows.heightfield=false");
    Project p = loadEffectiveProject("", sets, path, nullptr);
    p.scene.exportSettings.outDir = (std::filesystem::temp_directory_path() / "terralux_bench_shadow_cases").string();
    ProjectRenderer r(*f.ctx, p);
    if (near) {
        p.scene.camera.radius = double(r.defaultCamera().radius) / 3.0;
        r.setProject(p);
    }
    ShadowAgreement a;
    for (auto _ : state) a = measureShadowAgreement(r, 1280, 720);
    state.SetLabel(std::string(dem == 0 ? "sample" : dems[dem]) + ", sun " + std::to_string(sun) + "°, " + (near ? "near" : "far") +
                   (heightfield ? "" : ", maps only"));
    state.counters["acne_pct"] = 100.0 * a.acne;
    state.counters["disagree_pct"] = 100.0 * a.disagreeing;
    state.counters["mean_abs_diff"] = a.meanAbsDifference;
}
BENCHMARK(BM_ShadowCases)
    ->ArgsProduct({{0, 1, 2}, {5, 12, 35}, {0, 1}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->UseRealTime();

// Beauty at 1280 x 720 with shadows and fog each on or off (the defaults otherwise).
void BM_BeautyShadowsFog(benchmark::State& state) {
    Fixture& f = fixture();
    if (!f.renderer) {
        state.SkipWithError(f.error.c_str());
        return;
    }
    Project p = fixtureProject();
    p.scene.shadows.enabled = state.range(0) != 0;
    p.scene.fog.enabled = state.range(1) != 0;
    f.renderer->setProject(p);
    RenderRequest q;
    q.width = 1280;
    q.height = 720;
    f.renderer->render(q);  // pipelines and shadow maps of this variant
    double ms = 0;
    FrameCost cost;
    for (auto _ : state) {
        // A camera that moves a little every frame draws the shadow maps every frame, as orbiting
        // does; a turn too small to move the cascades' snapped projections would not, so the maps
        // are also marked for drawing.
        p.scene.camera.azimuthDeg += 0.5;
        f.renderer->setProject(p);
        f.renderer->renderer().redrawShadowMaps();
        ms += f.renderer->render(q).milliseconds;
        cost.add(f.renderer->renderer());
    }
    state.SetLabel(std::string("shadows ") + (state.range(0) ? "on" : "off") + ", fog " + (state.range(1) ? "on" : "off"));
    state.counters["frame_ms"] = ms / double(state.iterations());
    cost.report(state);
}
BENCHMARK(BM_BeautyShadowsFog)->Args({0, 0})->Args({1, 0})->Args({0, 1})->Args({1, 1})
    ->Unit(benchmark::kMillisecond)->MinTime(1.0)->UseRealTime();

// Beauty at 1920 x 1080 with each camera.antialiasing mode (off, fxaa, ssaa, msaa2, msaa4, msaa8): the frame and the antialias or resolve pass's
// own GPU time (aa_gpu_ms, where the device writes timestamps).
void BM_Antialiasing(benchmark::State& state) {
    Fixture& f = fixture();
    if (!f.renderer) {
        state.SkipWithError(f.error.c_str());
        return;
    }
    Project p = fixtureProject();
    p.scene.camera.antialiasing = Antialiasing(state.range(0));
    f.renderer->setProject(p);
    RenderRequest q;
    q.width = 1920;
    q.height = 1080;
    f.renderer->render(q);  // the pipeline and targets of this mode
    double ms = 0, pass = 0;
    int timed = 0;
    FrameCost cost;
    for (auto _ : state) {
        ms += f.renderer->render(q).milliseconds;
        cost.add(f.renderer->renderer());
        for (const auto& t : f.renderer->renderer().lastFrameTimings().passes)
            if (t.name == "antialias" || t.name == "resolve") pass += t.gpuMilliseconds, ++timed;
    }
    // The mode drawn: an msaa count the device lacks falls to the largest it has below.
    state.SetLabel(std::string(antialiasingName(f.renderer->renderer().drawnAntialiasing())) + " on " + f.ctx->deviceName());
    state.counters["frame_ms"] = ms / double(state.iterations());
    if (timed > 0) state.counters["aa_gpu_ms"] = pass / timed;
    cost.report(state);
    f.renderer->setProject(fixtureProject());
}
BENCHMARK(BM_Antialiasing)->DenseRange(0, 5)->Unit(benchmark::kMillisecond)->MinTime(1.0)->UseRealTime();

// The viewport's dynamic resolution: beauty over N42E001 at a 1350 x 990 window (the size the
// viewport had when it was measured on lavapipe) drawn at each of the scales it steps through,
// GPU and wall time; the label names the step the rule picks from the full-resolution frame for
// the device's budget (100 ms on a CPU device), and how close to it that step comes.
void BM_DynamicResolution(benchmark::State& state) {
    Fixture& f = fixture();
    if (!f.renderer) {
        state.SkipWithError(f.error.c_str());
        return;
    }
    const double scale = DynamicResolution::kScales[state.range(0)];
    const ScaledSize size = scaledSize(1350, 990, scale);
    RenderRequest q;
    q.width = size.width;
    q.height = size.height;
    f.renderer->render(q);  // the targets of this size
    double ms = 0;
    FrameCost cost;
    for (auto _ : state) {
        ms += f.renderer->render(q).milliseconds;
        cost.add(f.renderer->renderer());
    }
    // The rule as the viewport runs it: the full frame (the last refinement) and this scale.
    static double full = 0.0;
    const double budget = f.ctx->deviceType() == VK_PHYSICAL_DEVICE_TYPE_CPU ? 100.0 : 1000.0 / 60.0;
    std::string label = std::to_string(size.width) + "x" + std::to_string(size.height);
    if (cost.timed > 0) {
        const double gpu = cost.gpu / cost.timed;
        if (state.range(0) == 0) full = gpu;
        DynamicResolution rule(budget);
        rule.frameFinished(full, 1.0);
        rule.frameFinished(gpu, scale);
        state.counters["predicted_ms"] = rule.predictedMilliseconds(scale);
        label += ", budget " + std::to_string(int(budget)) + " ms: the rule picks scale " +
                 std::to_string(rule.interactiveScale()).substr(0, 5);
    }
    state.SetLabel(label + " on " + f.ctx->deviceName());
    state.counters["scale"] = scale;
    state.counters["frame_ms"] = ms / double(state.iterations());
    cost.report(state);
}
BENCHMARK(BM_DynamicResolution)->DenseRange(0, 4)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

// Source resolution (docs/ARCHITECTURE.md, "Source resolution"): N42E001 given the mesh budget of
// 2^20 vertices (stride 2), 1280 x 720, seen from 2 km over the ground (azimuth 210°, 15°), with
// the detail patches (arg 1) and without (arg 0): the frame's cost, its triangles, the detail
// patches' vertices and the screen error. The camera's target moves 6 km (a patch) back and forth
// between frames (arg 2 with the detail patches), so every frame draws a new set of them: what
// building and uploading them costs a moving camera.
void BM_SourceResolution(benchmark::State& state) {
    Fixture& f = fixture();
    if (!f.renderer) {
        state.SkipWithError(f.error.c_str());
        return;
    }
    static std::unique_ptr<ProjectRenderer> decimated;
    if (!decimated) {
        const Project p = fixtureProject();
        decimated = std::make_unique<ProjectRenderer>(*f.ctx, p, loadProjectTerrain(p), true, size_t(1) << 20);
        decimated->loadProbes(true);
    }
    TerrainRenderer& t = decimated->renderer();
    t.setSourceDetail(state.range(0) != 0);
    OrbitCamera camera = decimated->defaultCamera();
    camera.azimuthDeg = 210.0f;
    camera.elevationDeg = 15.0f;
    camera.radius = 2000.0f;
    RenderRequest q;
    q.width = 1280;
    q.height = 720;
    // 3: as the viewport draws, the levels chosen on a worker while the frame draws the set held.
    q.waitForLevelOfDetail = state.range(0) != 3;
    const glm::vec3 target = camera.target;
    decimated->render(q, camera);  // pipelines, maps and the first set of detail patches
    double ms = 0;
    FrameCost cost;
    int frame = 0;
    for (auto _ : state) {
        if (state.range(0) >= 2) camera.target.x = target.x + 6000.0f * float(++frame % 2);
        const RenderedImage img = decimated->render(q, camera);
        ms += img.milliseconds;
        cost.add(t);
        benchmark::DoNotOptimize(img.rgba.data());
    }
    static const char* labels[] = {"drawn grid alone", "detail patches, still camera", "detail patches, moving camera",
                                   "detail patches, moving camera, levels on a worker"};
    state.SetLabel(std::string(labels[state.range(0)]) + " on " + f.ctx->deviceName());
    state.counters["frame_ms"] = ms / double(state.iterations());
    state.counters["stride"] = t.meshStride();
    cost.report(state);
    t.setSourceDetail(true);
}
BENCHMARK(BM_SourceResolution)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->Iterations(4)->UseRealTime();

// Beauty at 1280 x 720 with the terrain surface's parts each on or off: horizon AO, the
// normal-variance specular and the micro-detail (shadows and fog off, so only these differ).
void BM_BeautySurface(benchmark::State& state) {
    Fixture& f = fixture();
    if (!f.renderer) {
        state.SkipWithError(f.error.c_str());
        return;
    }
    Project p = fixtureProject();
    p.scene.shadows.enabled = false;
    p.scene.fog.enabled = false;
    p.scene.ao.enabled = state.range(0) != 0;
    p.scene.terrain.specularAA = state.range(1) != 0;
    p.scene.detail.enabled = state.range(2) != 0;
    f.renderer->setProject(p);  // computes the AO field the first time it is asked for
    RenderRequest q;
    q.width = 1280;
    q.height = 720;
    f.renderer->render(q);
    double ms = 0;
    for (auto _ : state) ms += f.renderer->render(q).milliseconds;
    state.SetLabel(std::string("ao ") + (state.range(0) ? "on" : "off") + ", specular_aa " +
                   (state.range(1) ? "on" : "off") + ", detail " + (state.range(2) ? "on" : "off"));
    state.counters["frame_ms"] = ms / double(state.iterations());
}
BENCHMARK(BM_BeautySurface)->Args({0, 0, 0})->Args({1, 0, 0})->Args({0, 1, 0})->Args({0, 0, 1})->Args({1, 1, 1})
    ->Unit(benchmark::kMillisecond)->Iterations(5)->UseRealTime();

// A lake on N42E001 (the level 150 m over its lowest point, two waves) at 1280 x 720: the frame
// without water, with water reflecting the sky, and with the planar reflection at half and full
// resolution. The reflection's cost is the planar frame less the sky frame; the reference it is
// held to is the terrain pass at half resolution (the frame without water at 640 x 360).
void BM_Water(benchmark::State& state) {
    Fixture& f = fixture();
    if (!f.renderer) {
        state.SkipWithError(f.error.c_str());
        return;
    }
    Project p = fixtureProject();
    const int mode = int(state.range(0));
    p.scene.water.enabled = mode > 0;
    p.scene.water.level = double(f.renderer->heightfield().minHeight()) + 150.0;
    p.scene.water.waves = water::wavePreset("choppy lake");
    p.scene.water.reflection = mode == 1 ? WaterReflection::Sky : WaterReflection::Planar;
    p.scene.water.reflectionScale = mode == 3 ? 1.0 : 0.5;
    f.renderer->setProject(p);
    RenderRequest q;
    q.width = 1280;
    q.height = 720;
    auto frame = [&](RenderRequest r) {
        f.renderer->render(r);  // pipelines and targets first
        double ms = 0.0;
        for (int i = 0; i < 3; ++i) ms += f.renderer->render(r).milliseconds;
        return ms / 3.0;
    };
    double ms = 0;
    f.renderer->render(q);
    for (auto _ : state) ms += f.renderer->render(q).milliseconds;
    state.counters["frame_ms"] = ms / double(state.iterations());
    if (mode >= 2) {
        Project noWater = p;
        noWater.scene.water.reflection = WaterReflection::Sky;
        f.renderer->setProject(noWater);
        const double sky = frame(q);
        noWater.scene.water.enabled = false;
        f.renderer->setProject(noWater);
        RenderRequest half = q;
        half.width /= 2;
        half.height /= 2;
        const double terrainHalf = frame(half);
        state.counters["reflection_ms"] = state.counters["frame_ms"] - sky;
        state.counters["terrain_half_ms"] = terrainHalf;
        state.counters["reflection_over_terrain_half"] = (state.counters["frame_ms"] - sky) / terrainHalf;
    }
    static const char* labels[] = {"no water", "water, sky reflection", "water, planar reflection at 0.5",
                                   "water, planar reflection at 1.0"};
    state.SetLabel(labels[mode]);
    f.renderer->setProject(fixtureProject());
}
BENCHMARK(BM_Water)->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond)->Iterations(5)->UseRealTime();

// Reflection probes over N42E001 at 1280 x 720: the frame with the sky's specular alone, and with
// the default 4 x 4 probes in each encoding (baked at 8 rays per texel: the cost of drawing does
// not depend on the rays).
void BM_ReflectionProbes(benchmark::State& state) {
    Fixture& f = fixture();
    if (!f.renderer) {
        state.SkipWithError(f.error.c_str());
        return;
    }
    const int mode = int(state.range(0));
    std::shared_ptr<const ReflectionProbeSet> set;
    if (mode > 0) {
        Project p = fixtureProject();
        p.scene.reflectionProbes.enabled = true;
        p.scene.reflectionProbes.rayCount = 8;
        p.scene.reflectionProbes.encoding = mode == 1 ? ReflectionEncoding::Faces : ReflectionEncoding::Cubemap;
        p.scene.probeVolumes.clear();
        set = previewBake(p, f.renderer->heightfield(), nullptr).reflections;
    }
    f.renderer->setReflectionProbes(set);
    RenderRequest q;
    q.width = 1280;
    q.height = 720;
    double ms = 0;
    f.renderer->render(q);
    for (auto _ : state) ms += f.renderer->render(q).milliseconds;
    state.counters["frame_ms"] = ms / double(state.iterations());
    state.counters["gpu_bytes"] = double(f.renderer->renderer().reflectionBytes());
    static const char* labels[] = {"sky specular only", "4 x 4 probes, faces", "4 x 4 probes, cubemap 32"};
    state.SetLabel(labels[mode]);
    f.renderer->setReflectionProbes(nullptr);
}
BENCHMARK(BM_ReflectionProbes)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->Iterations(5)->UseRealTime();

// The LPV over N42E001 at 1280 x 720, the camera 4 km from the tile's centre so that the default
// cascades (5312 m and finer) fill most of the frame: beauty lit by the probes (the LPV off), by
// the LPV at quality 0, 1 and 2 (lighting.indirect lpv), and by the probes with four point lights
// in view (their direct light). Beside each LPV frame, its update: the volumes computed on the CPU
// for the camera (what the viewport's worker does: geometry, injection and, on a CPU device, the
// propagation), their upload, and on a GPU the propagation pass the first frame runs
// (timestamps).
void BM_Lpv(benchmark::State& state) {
    Fixture& f = fixture();
    if (!f.renderer) {
        state.SkipWithError(f.error.c_str());
        return;
    }
    const int mode = int(state.range(0));
    Project p = fixtureProject();
    p.scene.camera.radius = 4000.0;
    if (mode >= 1 && mode <= 3) {
        p.scene.lpv.enabled = true;
        p.scene.lighting.indirect = IndirectLighting::Lpv;
        p.scene.lpv.quality = mode - 1;
    }
    if (mode == 4) {
        const OrbitCamera camera = OrbitCamera::fromSettings(p.scene.camera, f.renderer->heightfield());
        const Heightfield& hf = f.renderer->heightfield();
        for (int i = 0; i < 4; ++i) {
            LocalLight light;
            const float x = camera.target.x + 500.0f * float(i - 2), z = camera.target.z;
            light.position = glm::vec3(x, hf.surfaceHeight(x, z) + 100.0f, z);
            light.range = 600.0;
            light.intensity = 3.0e4 / kSceneUnitsPerLux;
            p.scene.lights.push_back(light);
        }
    }
    f.renderer->setProject(p);
    RenderRequest q;
    q.width = 1280;
    q.height = 720;
    double updateMs = 0, uploadMs = 0;
    if (const auto job = f.renderer->lpvJob(q, f.renderer->defaultCamera())) {  // the project's camera
        using Clock = std::chrono::steady_clock;
        const auto t0 = Clock::now();
        auto volumes = job->run();
        const auto t1 = Clock::now();
        f.renderer->setLpv(std::move(volumes), job->key);
        const auto t2 = Clock::now();
        updateMs = std::chrono::duration<double, std::milli>(t1 - t0).count();
        uploadMs = std::chrono::duration<double, std::milli>(t2 - t1).count();
    }
    f.renderer->render(q);  // this variant's pipeline, and the propagation
    const double propagationMs = f.renderer->renderer().lpvPropagationMilliseconds().value_or(0.0);
    double ms = 0;
    for (auto _ : state) ms += f.renderer->render(q).milliseconds;
    static const char* labels[] = {"probes, LPV off", "LPV quality 0", "LPV quality 1", "LPV quality 2",
                                   "probes and 4 point lights"};
    state.SetLabel(std::string(labels[mode]) + " on " + f.ctx->deviceName());
    state.counters["frame_ms"] = ms / double(state.iterations());
    state.counters["update_ms"] = updateMs;
    state.counters["upload_ms"] = uploadMs;
    state.counters["propagation_ms"] = propagationMs;
    f.renderer->setProject(fixtureProject());
}
BENCHMARK(BM_Lpv)->DenseRange(0, 4)->Unit(benchmark::kMillisecond)->Iterations(5)->UseRealTime();

// One LPV update for BM_Lpv's camera, by its parts: the geometry and the injection on the CPU
// (update_cpu_ms), the upload (upload_ms) and the propagation pass on the GPU (the benchmark's
// time, from timestamps), against the same steps on the CPU (cpu_propagation_ms:
// lpv::propagationStep as Volumes::propagate takes them, oneTBB on this machine's cores). Args: cascades, iterations; quality and weight
// change no step's cost.
void BM_LpvUpdate(benchmark::State& state) {
    Fixture& f = fixture();
    if (!f.renderer) {
        state.SkipWithError(f.error.c_str());
        return;
    }
    if (!(f.ctx->timestampPeriod() > 0.0)) {
        state.SkipWithError("the device writes no timestamps");
        return;
    }
    Project p = fixtureProject();
    p.scene.camera.radius = 4000.0;
    p.scene.lpv.enabled = true;
    p.scene.lighting.indirect = IndirectLighting::Lpv;
    p.scene.lpv.cascades = int(state.range(0));
    p.scene.lpv.propagationIterations = int(state.range(1));
    f.renderer->setProject(p);
    RenderRequest q;
    q.width = 1280;
    q.height = 720;
    const auto job = f.renderer->lpvJob(q, f.renderer->defaultCamera());
    if (!job) {
        state.SkipWithError("no LPV job");
        return;
    }
    using Clock = std::chrono::steady_clock;
    const auto ms = [](Clock::time_point a, Clock::time_point b) {
        return std::chrono::duration<double, std::milli>(b - a).count();
    };
    const float weight = lpv::propagationStepWeight(p.scene.lpv.propagationWeight);
    double cpuPart = 0, upload = 0, cpuSteps = 0;
    for (auto _ : state) {
        const auto t0 = Clock::now();
        const std::shared_ptr<const lpv::Volumes> volumes = job->run(lpv::Propagation::Renderer);
        const auto t1 = Clock::now();
        f.renderer->setLpv(nullptr, "");
        f.renderer->setLpv(volumes, job->key);
        const auto t2 = Clock::now();
        f.renderer->render(q);
        const std::optional<double> gpu = f.renderer->renderer().lpvPropagationMilliseconds();
        state.SetIterationTime(gpu.value_or(0.0) * 1e-3);
        const auto t3 = Clock::now();
        for (const lpv::Cascade& c : volumes->cascades()) {
            lpv::LightVolume current = c.injected, next;
            for (int it = 0; it < p.scene.lpv.propagationIterations; ++it) {
                lpv::propagationStep(c.geometry, current, next, weight, it > 0);
                current.swap(next);
            }
        }
        cpuSteps += ms(t3, Clock::now());
        cpuPart += ms(t0, t1);
        upload += ms(t1, t2);
    }
    const double n = double(state.iterations());
    state.SetLabel("c" + std::to_string(state.range(0)) + " it" + std::to_string(state.range(1)) + " on " +
                   f.ctx->deviceName());
    state.counters["update_cpu_ms"] = cpuPart / n;
    state.counters["upload_ms"] = upload / n;
    state.counters["cpu_propagation_ms"] = cpuSteps / n;
    f.renderer->setProject(fixtureProject());
}
BENCHMARK(BM_LpvUpdate)
    ->Args({3, 4})->Args({1, 4})->Args({2, 4})->Args({4, 4})->Args({3, 2})->Args({3, 8})->Args({3, 16})
    ->Unit(benchmark::kMillisecond)->Iterations(3)->UseManualTime();

// Last, as it binds a bake of its own. Every feature on (shadows, fog, water with planar reflection, probes, reflection probes, the LPV
// lighting the terrain, AO, detail) at 1920 x 1080 with a camera moving a little every frame: the
// GPU time of each pass of the frame graph as a counter of its own (gpu_<pass>_ms), beside the
// frame's wall, GPU and host time.
void BM_FramePasses(benchmark::State& state) {
    Fixture& f = fixture();
    if (!f.renderer) {
        state.SkipWithError(f.error.c_str());
        return;
    }
    Project p = fixtureProject();
    p.scene.water.enabled = true;
    p.scene.water.level = double(f.renderer->heightfield().minHeight()) + 150.0;
    p.scene.water.waves = water::wavePreset("choppy lake");
    p.scene.reflectionProbes.enabled = true;
    p.scene.lpv.enabled = true;
    p.scene.lighting.indirect = IndirectLighting::Both;
    f.renderer->setProject(p);
    f.renderer->loadProbes(true);  // bakes the reflection probes and the water's light first
    RenderRequest q;
    q.width = 1920;
    q.height = 1080;
    f.renderer->render(q);  // pipelines, maps, volumes
    double ms = 0;
    FrameCost cost;
    for (auto _ : state) {
        p.scene.camera.azimuthDeg += 0.5;
        f.renderer->setProject(p);
        f.renderer->renderer().redrawShadowMaps();  // as a moving camera does (BM_BeautyShadowsFog)
        ms += f.renderer->render(q).milliseconds;
        cost.add(f.renderer->renderer());
    }
    state.SetLabel("every feature on, 1920x1080, on " + f.ctx->deviceName());
    state.counters["frame_ms"] = ms / double(state.iterations());
    cost.report(state);
    f.renderer->setProject(fixtureProject());
}
// What metering costs a moving camera: beauty at 1280 x 720, the camera turning every frame, with
// manual exposure (0) and histogram metering (1), which draws the 128-pixel meter first and then
// the frame; the two sizes keep their targets (TerrainRenderer::targetAllocations, counted).
void BM_MeteredFrame(benchmark::State& state) {
    Fixture& f = fixture();
    if (!f.renderer) {
        state.SkipWithError(f.error.c_str());
        return;
    }
    Project p = fixtureProject();
    p.scene.camera.exposureMode = state.range(0) ? ExposureMode::Histogram : ExposureMode::Manual;
    f.renderer->setProject(p);
    RenderRequest q;
    q.width = 1280;
    q.height = 720;
    f.renderer->render(q);
    const size_t allocations = f.renderer->renderer().targetAllocations();
    FrameCost cost;
    for (auto _ : state) {
        p.scene.camera.azimuthDeg += 0.5;
        f.renderer->setProject(p);
        f.renderer->render(q);
        cost.add(f.renderer->renderer());
    }
    state.SetLabel(std::string(state.range(0) ? "histogram" : "manual") + " on " + f.ctx->deviceName());
    cost.report(state);
    state.counters["target_allocations"] = double(f.renderer->renderer().targetAllocations() - allocations);
    f.renderer->setProject(fixtureProject());
}
BENCHMARK(BM_MeteredFrame)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->MinTime(1.0)->UseRealTime();

// At least a second of frames: a GPU's clocks ramp up under load, and five frames of an idle
// one read up to twice the time (docs/gpu_frame_cost.md).
BENCHMARK(BM_FramePasses)->Unit(benchmark::kMillisecond)->MinTime(1.0)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
