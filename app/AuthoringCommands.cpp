#include "AuthoringCommands.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <optional>
#include <vector>

#include "CommandLineSupport.h"
#include "ImageFile.h"
#include "Project.h"
#include "ProjectRenderer.h"
#include "TerrainLoading.h"
#include "scene/DebugViews.h"
#include "vk/VulkanContext.h"

namespace terralux {
namespace {

using namespace cli;

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n == 0 ? 0.0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Warm frames of one request, each figure the median over them (per pass by name, in the first
// frame's order).
struct ProfileSummary {
    FrameTimings timings;
    double wallMilliseconds = 0.0;
    int frames = 0;
};

ProfileSummary profileWarmFrames(ProjectRenderer& renderer, const RenderRequest& request) {
    constexpr double kMinSeconds = 1.0;
    constexpr int kMinFrames = 3, kMaxFrames = 200;
    std::vector<FrameTimings> frames;
    std::vector<double> wall;
    double spent = 0.0;
    while (int(frames.size()) < kMinFrames || (spent < kMinSeconds * 1000.0 && int(frames.size()) < kMaxFrames)) {
        const double ms = renderer.render(request).milliseconds;
        wall.push_back(ms);
        spent += ms;
        frames.push_back(renderer.renderer().lastFrameTimings());
    }
    ProfileSummary s;
    s.frames = int(frames.size());
    s.wallMilliseconds = median(wall);
    auto of = [&](auto get) {
        std::vector<double> v;
        for (const auto& f : frames) v.push_back(get(f));
        return median(v);
    };
    s.timings = frames.front();
    s.timings.recordMilliseconds = of([](const FrameTimings& f) { return f.recordMilliseconds; });
    s.timings.readbackMilliseconds = of([](const FrameTimings& f) { return f.readbackMilliseconds; });
    s.timings.gpuMilliseconds = of([](const FrameTimings& f) { return f.gpuMilliseconds; });
    for (auto& pass : s.timings.passes)
        pass.gpuMilliseconds = of([&](const FrameTimings& f) {
            for (const auto& p : f.passes)
                if (p.name == pass.name) return p.gpuMilliseconds;
            return 0.0;
        });
    return s;
}

int commandRender(const Args& a) {
    const QStringList positional = a.parser.positionalArguments();
    if (positional.size() > 1) throw UsageError("--render takes one PROJECT");
    if (!a.parser.isSet(a.out)) throw UsageError("--render needs --out IMAGE (.png or .exr)");
    const std::filesystem::path image = std::filesystem::absolute(str(a.parser.value(a.out)));
    const std::string ext = image.extension().string();
    if (ext != ".png" && ext != ".exr")
        throw UsageError("--out " + image.string() + ": extension must be .png or .exr");
    RenderRequest request;
    request.width = 1280;
    request.height = 720;
    if (a.parser.isSet(a.size)) {
        const std::string v = str(a.parser.value(a.size));
        unsigned w = 0, h = 0;
        char x = 0, extra = 0;
        if (std::sscanf(v.c_str(), "%u%c%u%c", &w, &x, &h, &extra) != 3 || x != 'x' || w < 1 ||
            h < 1 || w > 16384 || h > 16384)
            throw UsageError("--size " + v + ": expected WxH, each in [1, 16384]");
        request.width = w;
        request.height = h;
    }
    if (a.parser.isSet(a.debugView)) {
        const std::string v = str(a.parser.value(a.debugView));
        const auto view = findDebugView(v);
        if (!view) throw UsageError("--debug-view " + v + ": not one of " + debugViewList());
        request.debugView = view->number;
    }
    if (a.parser.isSet(a.time)) {
        bool ok = false;
        const double t = a.parser.value(a.time).toDouble(&ok);
        if (!ok || !std::isfinite(t) || t < 0.0 || t > 1.0e6)
            throw UsageError("--time " + str(a.parser.value(a.time)) + ": expected seconds, a number in [0, 1000000]");
        request.time = t;
    }
    std::optional<ScenarioView> scenario;
    if (a.parser.isSet(a.scenario)) {
        const std::string v = str(a.parser.value(a.scenario));
        const QStringList parts = a.parser.value(a.scenario).split(',');
        bool ok = parts.size() == 1 || parts.size() == 3;
        ScenarioView view;
        view.a = view.b = str(parts[0]);
        if (ok && parts.size() == 3) {
            view.b = str(parts[1]);
            const double t = parts[2].toDouble(&ok);
            ok = ok && std::isfinite(t) && t >= 0.0 && t <= 1.0;
            view.blend = float(t);
        }
        if (!ok) throw UsageError("--scenario " + v + ": expected NAME, or NAME,TO,T with T in [0, 1]");
        scenario = view;
    }
    request.probes = !a.parser.isSet(a.noProbes);
    request.linearOutput = ext == ".exr";
    for (const QString& o : a.parser.values(a.overlay))
        for (const QString& part : o.split(',')) {
            if (part == "probes")
                request.probePositions = true;
            else if (part == "leaves")
                request.leaves = true;
            else
                throw UsageError("--overlay " + str(o) + ": '" + str(part) +
                                 "' is not one of probes, leaves");
        }

    std::vector<std::string> warnings, sets;
    for (const QString& s : a.parser.values(a.set)) sets.push_back(str(s));
    if (a.parser.isSet(a.camera)) {
        const QStringList parts = a.parser.value(a.camera).split(',');
        bool ok = parts.size() == 2 || parts.size() == 3;
        double v[3] = {0, 0, 0};
        for (int i = 0; ok && i < parts.size(); ++i) v[i] = parts[i].toDouble(&ok);
        if (!ok)
            throw UsageError("--camera " + str(a.parser.value(a.camera)) +
                             ": expected AZ,EL[,RADIUS] in degrees and metres");
        sets.push_back("camera.azimuth_deg=" + std::to_string(v[0]));
        sets.push_back("camera.elevation_deg=" + std::to_string(v[1]));
        if (parts.size() == 3) sets.push_back("camera.radius=" + std::to_string(v[2]));
    }
    const Project project = loadEffectiveProject(positional.isEmpty() ? "" : str(positional[0]), sets,
                                                 a.parser.isSet(a.dem) ? str(a.parser.value(a.dem)) : "",
                                                 &warnings);
    for (const auto& w : warnings) std::cerr << programName() << ": warning: " << w << "\n";

    if (scenario) {
        // A name the project lacks is refused by name, with the scenarios it has.
        for (const std::string& name : {scenario->a, scenario->b}) (void)scenarioScene(project.scene, name);
    }

    vk::ContextOptions options;
    if (a.parser.isSet(a.device)) options.device = str(a.parser.value(a.device));
    std::unique_ptr<vk::VulkanContext> ctx;
    try {
        ctx = std::make_unique<vk::VulkanContext>(options);
    } catch (const vk::VulkanUnavailable& e) {
        std::cerr << programName() << ": " << e.what() << "; --bake works without one\n";
        return kExitRuntime;
    }
    ProjectRenderer renderer(*ctx, project);
    if (scenario) renderer.setScenarioView(*scenario);
    std::string note;
    std::vector<std::string> probeWarnings;
    const size_t volumes =
        request.probes ? renderer.loadProbes(!a.parser.isSet(a.noRebake), &note, &probeWarnings) : 0;
    if (!note.empty() && !a.parser.isSet(a.quiet)) std::cerr << programName() << ": " << note << "\n";
    if (request.probes && volumes == 0) {
        // --no-rebake with nothing baked: say so, rather than call a missing bake stale.
        std::cerr << programName() << ": warning: " << project.outDir().string()
                  << " holds no bake to draw (--no-rebake): " << renderer.staleBake().front()
                  << "; rendering without probes\n";
    } else if (!renderer.staleBake().empty()) {
        std::cerr << programName() << ": warning: " << project.outDir().string() << " holds a stale bake (--no-rebake draws it):";
        for (const auto& d : renderer.staleBake()) std::cerr << (&d == &renderer.staleBake().front() ? " " : "; ") << d;
        std::cerr << "\n";
    }
    // Only the views that need the diagnostics complain about their absence.
    if (findDebugView(request.debugView)->needs.probeDiagnostics)
        for (const auto& w : probeWarnings) std::cerr << programName() << ": warning: " << w << "\n";
    if (request.debugView == kViewInterpolationError && volumes > 0 && probeWarnings.empty() &&
        !renderer.hasErrorMap())
        std::cerr << programName() << ": note: this bake measured no interpolation-error map "
                     "(bake.error_map_resolution = 0, or no volume over the terrain): view "
                  << kViewInterpolationError << " is grey\n";
    // A PNG is read back as its 8-bit codes: no float frame is made to be rounded again.
    request.bytes = encodingFor(image) == ImageEncoding::Display8;
    const RenderedImage img = renderer.render(request);
    if (request.bytes)
        writeImage(image, img.width, img.height, img.bytes);
    else
        writeImage(image, img.width, img.height, img.rgba);
    // The first frame builds pipelines, maps and volumes; the profile is of the same frame warm,
    // drawn again for at least a second (a GPU's clocks ramp up under load) and at least three
    // times, the median of each figure reported: one warm frame on an idle GPU read up to 5x high.
    std::optional<ProfileSummary> warm;
    if (a.parser.isSet(a.profile)) warm = profileWarmFrames(renderer, request);
    const auto view = findDebugView(std::to_string(request.debugView));
    std::cout << "rendered " << image.string() << " (" << img.width << "x" << img.height << ", view "
              << view->number << " " << view->name << ", " << volumes << " probe volume(s), "
              << ctx->deviceName() << ", " << fixed(img.milliseconds, 1) << " ms)\n";
    // The level of detail the image drew (docs/ARCHITECTURE.md, "Level of detail").
    const TerrainRenderer& terrain = renderer.renderer();
    // Out of the DEM's own triangles (two a cell), which a decimated drawn grid has fewer of than
    // the detail patches near the camera can add.
    const Heightfield& dem = renderer.heightfield();
    const size_t demTriangles = 2 * size_t(std::max(dem.width() - 1, 0)) * size_t(std::max(dem.depth() - 1, 0));
    std::cout << "terrain: " << terrain.lastLod().triangles << " of the DEM's " << demTriangles
              << " triangles at the level of detail, within " << fixed(terrain.lastLod().screenErrorPixels, 2)
              << " px of it";
    if (terrain.meshStride() > 1) {
        const auto& detail = terrain.lastLod().detail;
        const auto own = std::count_if(detail.begin(), detail.end(), [](int8_t d) { return d >= 0; });
        const int k = terrain.meshStride();
        const char* suffix = k % 100 / 10 == 1 ? "th" : k % 10 == 1 ? "st" : k % 10 == 2 ? "nd" : k % 10 == 3 ? "rd" : "th";
        std::cout << " (drawn from every " << k << suffix << " row and column; " << own
                  << " patch(es) from the DEM's own vertices, " << terrain.lastLod().detailVertices << " of them)";
    }
    std::cout << "\n";
    // An msaa count the device lacks is drawn with the largest it has below (or fxaa): say so.
    const Antialiasing asked = project.scene.camera.antialiasing, drawn = renderer.renderer().drawnAntialiasing();
    if (msaaSamples(asked) > 1 && drawn != Antialiasing::Off && drawn != asked)
        std::cout << "anti-aliasing: " << antialiasingName(drawn) << " (" << ctx->deviceName() << " has no "
                  << antialiasingName(asked) << ")\n";
    if (project.scene.camera.exposureMode != ExposureMode::Manual && std::isfinite(renderer.meteredEv100()))
        std::cout << "exposure: EV100 " << fixed(renderer.meteredEv100(), 2) << " metered ("
                  << exposureModeName(project.scene.camera.exposureMode) << "), compensation "
                  << fixed(project.scene.camera.exposureEv, 1) << " EV\n";
    if (warm) {
        const FrameTimings& t = warm->timings;
        std::cout << "profile (the frame drawn " << warm->frames << " times more, warm; medians):\n";
        if (t.gpuTimed()) {
            // Names padded to the longest, then the milliseconds right-aligned in their own column.
            size_t width = std::string("GPU total").size();
            for (const auto& p : t.passes) width = std::max(width, p.name.size());
            auto row = [&](const std::string& name, const std::string& value) {
                std::cout << "  " << std::left << std::setw(int(width)) << name << std::right << " " << std::setw(9)
                          << value << "\n";
            };
            row("pass", "GPU ms");
            for (const auto& p : t.passes) row(p.name, fixed(p.gpuMilliseconds, 3));
            row("GPU total", fixed(t.gpuMilliseconds, 3));
        } else {
            std::cout << "  GPU: " << ctx->deviceName() << " writes no timestamps\n";
        }
        std::cout << "  host: recording " << fixed(t.recordMilliseconds, 2) << " ms, read-back conversion "
                  << fixed(t.readbackMilliseconds, 2) << " ms; wall " << fixed(warm->wallMilliseconds, 1)
                  << " ms warm, " << fixed(img.milliseconds, 1) << " ms cold\n";
    }
    // The LPV views' own exposure, printed with the view so the image can be read as numbers.
    if (view->number == kViewLpvCascade0 || view->number == kViewLpvAll) {
        if (const std::optional<double> range = renderer.renderer().lpvViewRange())
            std::cout << "LPV view scale: E/pi / " << std::setprecision(4) << *range
                      << " W/(m2 sr) through the display curve ("
                      << (request.linearOutput ? "this EXR holds E/pi unscaled" : "1.0 shows as 0.9") << ")\n";
        else
            std::cout << "LPV view scale: the light propagation volumes hold no light here\n";
    }
    return kExitOk;
}

int commandStudy(const Args& a, const StudyPlotWriter& writePlot) {
    const QStringList positional = a.parser.positionalArguments();
    if (positional.size() > 1) throw UsageError("--study takes one PROJECT");
    StudyOptions options;
    if (a.parser.isSet(a.budget)) {
        bool ok = false;
        options.budgetSeconds = a.parser.value(a.budget).toDouble(&ok);
        if (!ok || !(options.budgetSeconds >= kMinStudyBudget && options.budgetSeconds <= kMaxStudyBudget))
            throw UsageError("--budget " + str(a.parser.value(a.budget)) + ": must be a number of seconds in [" +
                             fixed(kMinStudyBudget, 0) + ", " + fixed(kMaxStudyBudget, 0) + "]");
    }
    options.threads = a.parser.isSet(a.threads) ? a.parser.value(a.threads).toInt() : 0;
    if (a.parser.isSet(a.device)) options.device = str(a.parser.value(a.device));
    std::vector<std::string> sets, warnings;
    for (const QString& s : a.parser.values(a.set)) sets.push_back(str(s));
    const Project project = loadEffectiveProject(positional.isEmpty() ? "" : str(positional[0]), sets,
                                                 a.parser.isSet(a.dem) ? str(a.parser.value(a.dem)) : "", &warnings);
    for (const auto& w : warnings) std::cerr << programName() << ": warning: " << w << "\n";
    std::filesystem::path outDir;
    if (a.parser.isSet(a.out)) {
        const std::string dir = str(a.parser.value(a.out));
        if (dir.empty()) throw UsageError("--out: must name a folder");
        outDir = std::filesystem::absolute(dir).lexically_normal();
    } else {
        outDir = project.resolve("study");
    }
    std::error_code ec;
    if (std::filesystem::exists(outDir, ec) && !std::filesystem::is_directory(outDir, ec))
        throw UsageError("--out " + outDir.string() + ": exists and is not a folder");

    installInterruptHandlers();
    ProgressPrinter printer(a.parser.isSet(a.quiet));
    StudyResult result;
    try {
        result = runStudy(project, options, std::ref(printer), &gInterrupted);
    } catch (const BakeCancelled&) {
        std::cerr << "\n" << programName() << ": interrupted; nothing written\n";
        return kExitInterrupted;
    }
    const auto files = writeStudy(result, outDir, writePlot);
    std::cout << studySummary(result);
    std::cout << "wrote " << outDir.string() << ":\n";
    for (const auto& f : files) std::cout << "  " << f.filename().string() << "\n";
    return kExitOk;
}


// A Vulkan failure is the work failing (exit 3), said in one line.
int guarded(const std::function<int()>& command) {
    try {
        return command();
    } catch (const vk::VulkanError& e) {
        std::cerr << programName() << ": " << e.what() << "\n";
        return kExitRuntime;
    }
}

}  // namespace

AuthoringCommands authoringCommands(StudyPlotWriter writeStudyPlot) {
    AuthoringCommands c;
    c.render = [](const Args& a) { return guarded([&] { return commandRender(a); }); };
    c.study = [writeStudyPlot](const Args& a) { return guarded([&] { return commandStudy(a, writeStudyPlot); }); };
    return c;
}

}  // namespace terralux
