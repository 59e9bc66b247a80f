#include "PreviewBake.h"


#include "EnvironmentImage.h"
#include "SceneLighting.h"
#include "TerrainLoading.h"
#include "bake/AdaptivePlacement.h"
#include "bake/DiffuseBake.h"
#include "bake/HeightfieldTracer.h"
#include "bake/ProbeDiagnostics.h"
#include "bake/ProbePlacement.h"
#include "bake/ReflectionBake.h"
#include "bake/SphereSampling.h"

namespace terralux {

namespace {
// The draft's error map: enough to see where interpolation fails, at a quarter of the points.
constexpr int kPreviewErrorMapResolution = 32;
// Rays per cube texel of the draft reflection probes.
constexpr int kPreviewReflectionRays = 4;
}  // namespace

PreviewBake previewBake(const Project& project, const Heightfield& hf, const std::atomic<bool>* cancel) {
    const SceneDescription& scene = project.scene;
    // A map that cannot be read: the preview lights with the constant albedo, as the viewport
    // draws it (ProjectRenderer::albedoError says why); a bake reports the error.
    const BakeScene traced = bakeSceneOf(project, hf, true);
    const BakeLighting& lighting = traced.lighting;
    const BakeQuality q = qualityPreset(QualityPreset::Draft);
    const BakeControl control{nullptr, cancel};
    const IrradianceCache cache(lighting, q.cacheResolution, q.cacheRays, q.sunSamples, q.bounces - 1, control);

    PreviewBake preview;
    std::vector<GpuProbeVolume>& out = preview.volumes;
    uint64_t index = 0;
    for (const auto& v : scene.probeVolumes) {
        if (!v.enabled) continue;
        const ProbeLayout layout = placeProbes(v, hf);
        const uint64_t seed = splitmix64(0x7E77A1ABull + index++);
        const ProbeBake bake = bakeProbes(lighting, &cache, q.bounces, layout.positions, layout.valid,
                                          q.rays, seed, control);
        // Diagnostics as the bake writes them, with a coarser error map.
        ProbeDiagnostics d = describeProbes(layout, bake.standardError);
        const ProbeBaker baker = seededBaker(lighting, &cache, q.bounces, q.rays, seed, control);
        d.errorMap = measureErrorMap(layout, bake.sh, hf, baker,
                                     std::min(scene.bake.errorMapResolution, kPreviewErrorMapResolution),
                                     errorMapHeight(v, layout), seed);
        GpuProbeVolume g;
        g.name = v.name;
        g.dims = glm::uvec3(layout.cellDims[0], layout.cellDims[1], layout.cellDims[2]);
        g.origin = layout.cellOrigin;
        g.spacing = layout.cellSize;
        g.fallbackBlendDistance = layout.fallbackBlendDistance;
        g.scale = float(scene.exportSettings.defaultScale);
        // Valid probes only, as in .shprobe.
        for (size_t i = 0; i < layout.positions.size(); ++i)
            if (layout.valid[i]) g.coeffs.push_back(bake.sh[i].c);
        g.occupancy = layout.compactedOccupancy();
        g.diagnostics = std::move(d);
        out.push_back(std::move(g));
    }
    if (scene.reflectionProbes.enabled) {
        // The bake's probes at the draft's rays: the same cube size and encoding, so the preview
        // shows what the encoding keeps.
        ReflectionProbeSettings s = scene.reflectionProbes;
        s.rayCount = std::min(s.rayCount, kPreviewReflectionRays);
        const ReflectionLighting light{&lighting, &cache, q.bounces, groundRadiance(lighting, s.groundColor)};
        auto set = std::make_shared<ReflectionProbeSet>(
            bakeReflectionProbes(light, s, placeReflectionProbes(s, hf), splitmix64(0x2EF1EC7ull), control));
        toEncoding(*set, s.encoding);
        preview.reflections = std::move(set);
    }
    return preview;
}

std::vector<GpuProbeVolume> previewProbes(const Project& project, const Heightfield& hf,
                                          const std::atomic<bool>* cancel) {
    Project volumesOnly = project;
    volumesOnly.scene.reflectionProbes.enabled = false;
    return previewBake(volumesOnly, hf, cancel).volumes;
}

}  // namespace terralux
