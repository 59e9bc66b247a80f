#include "RenderJob.h"

#include <numbers>

#include "BakeJob.h"
#include "SceneLighting.h"
#include "ShProbeFile.h"
#include "TerrainLoading.h"
#include "bake/ProbePlacement.h"
#include "render/OrbitCamera.h"

namespace terralux {


ProjectRenderer::ProjectRenderer(vk::VulkanContext& ctx, const Project& project)
    : ProjectRenderer(ctx, project, loadProjectTerrain(project)) {}

ProjectRenderer::ProjectRenderer(vk::VulkanContext& ctx, const Project& project,
                                 DemImportResult terrain)
    : project_(project), terrain_(std::move(terrain)) {
    renderer_ = std::make_unique<TerrainRenderer>(ctx, terrain_.heightfield);
    setProject(project);
}

void ProjectRenderer::setProject(const Project& project) {
    project_ = project;
    const SceneDescription& scene = project_.scene;
    const BakeLighting lighting = lightingOf(project_);
    base_.albedo = lighting.albedo;
    base_.sun = lighting.sun;
    base_.skySh = lighting.sky.sh();
    base_.camera = OrbitCamera::fromSettings(scene.camera, terrain_.heightfield);
    std::vector<glm::vec4> positions;
    for (const auto& v : scene.probeVolumes) {
        if (!v.enabled) continue;
        try {
            const ProbeLayout layout = placeProbes(v, terrain_.heightfield);
            for (size_t i = 0; i < layout.positions.size(); ++i)
                positions.emplace_back(layout.positions[i], layout.valid[i] ? 1.0f : 0.0f);
        } catch (const PlacementError&) {
            // Settings the bake would refuse: no markers for that volume.
        }
    }
    renderer_->setProbePositions(positions);
}

ProjectRenderer::~ProjectRenderer() = default;

size_t ProjectRenderer::loadProbes(bool bakeIfMissing, std::string* note) {
    const SceneDescription& scene = project_.scene;
    const std::filesystem::path dir = project_.outDir() / "sh_coeffs";
    bool missing = false;
    for (const auto& v : scene.probeVolumes)
        if (v.enabled && !std::filesystem::exists(dir / (v.name + ".shprobe"))) missing = true;
    if (missing && bakeIfMissing) {
        BakeRequest request;
        request.project = project_;
        runBake(request, nullptr, nullptr);
        if (note) *note = "baked " + project_.outDir().string() + " first (no earlier bake there)";
    }
    std::vector<GpuProbeVolume> volumes;
    for (const auto& v : scene.probeVolumes) {
        if (!v.enabled) continue;
        const auto path = dir / (v.name + ".shprobe");
        if (!std::filesystem::exists(path)) continue;
        const ShProbeGrid g = readShProbeFile(path);
        GpuProbeVolume gv;
        gv.dims = g.dims;
        gv.origin = g.origin;
        gv.spacing = g.spacing;
        gv.occupancy = g.occupancy;
        gv.scale = g.defaultScale;
        gv.irradianceEncoded = scene.bake.encoding == ShEncoding::Irradiance;
        // LIGHTING.md default: twice the smallest probe spacing, which is the cell edge here.
        gv.fallbackBlendDistance = v.fallbackBlendDistance ? float(*v.fallbackBlendDistance)
                                                           : 2.0f * g.spacing;
        for (const auto& r : g.probes) gv.coeffs.push_back(r.coeffs);
        volumes.push_back(std::move(gv));
    }
    renderer_->setProbeVolumes(volumes);
    return volumes.size();
}

RenderedImage ProjectRenderer::render(const RenderRequest& r) { return render(r, base_.camera); }

RenderedImage ProjectRenderer::render(const RenderRequest& r, const OrbitCamera& camera) {
    RenderSettings s = base_;
    s.camera = camera;
    s.width = r.width;
    s.height = r.height;
    s.debugView = r.debugView;
    s.probes = r.probes;
    s.linearOutput = r.linearOutput;
    s.showProbePositions = r.probePositions;
    return renderer_->render(s);
}

}  // namespace terralux
