#include "render/features/Lpv.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

namespace terralux::features {

using namespace frame;

std::vector<blocks::LocalLightRecord> packLocalLights(const std::vector<LocalLight>& lights, bool used) {
    std::vector<blocks::LocalLightRecord> records(std::max<size_t>(used ? lights.size() : 0, 1));
    for (size_t i = 0; used && i < lights.size(); ++i) {
        const LocalLight& l = lights[i];
        blocks::LocalLightRecord& r = records[i];
        const bool spot = l.type == LocalLightType::Spot;
        r.position = l.position;
        r.range = float(l.range);
        r.emitted = l.color * float(l.intensity);
        r.spot = spot ? 1.0f : 0.0f;
        const float len = glm::length(l.direction);
        r.direction = len > 0.0f ? l.direction / len : glm::vec3(0.0f, -1.0f, 0.0f);
        const float cosOuter = std::cos(glm::radians(float(l.outerConeDeg)));
        const float cosInner = std::cos(glm::radians(float(l.innerConeDeg)));
        r.cosOuter = cosOuter;
        r.invConeWidth = 1.0f / std::max(0.001f, cosInner - cosOuter);
    }
    return records;
}

blocks::LpvBlock packLpv(const Frame& f) {
    blocks::LpvBlock block = f.lpvVolumes ? f.lpvVolumes->block : blocks::LpvBlock{};
    block.lightCount = f.localLights ? int(f.s.lights.size()) : 0;
    block.addsToAmbient = f.lpvVolumes && f.s.lpvLight && f.view.needs.sceneLights ? 1.0f : 0.0f;
    return block;
}

void addLpvPropagationPass(Frame& f, std::function<void(VkCommandBuffer)> record) {
    if (!f.lpvVolumes || f.lpvVolumes->steps <= 0) return;
    PassInfo info{"lpv-propagate",
                  {{kLpvWork, Access::ComputeStorageReadWrite},
                   {kLpvScales, Access::ComputeStorageReadWrite},
                   {kLpvGeometry, Access::ComputeStorageRead},
                   {kLpvLight, Access::ComputeStorageReadWrite}},
                  f.lpvVolumes->propagationSet.bindingNames()};
    f.g.graph.addPass(std::move(info), std::move(record));
}

}  // namespace terralux::features
