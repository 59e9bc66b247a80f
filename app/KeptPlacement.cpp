#include "KeptPlacement.h"

#include <optional>
#include <string>

#include "Project.h"
#include "terrain/DerivedCache.h"

namespace terralux {
namespace {

struct Placed {
    std::optional<ProbeLayout> layout;
    std::string refusal;  // placeProbes' message where it refused the volume
};

DerivedCache<Placed>& kept() {
    static DerivedCache<Placed> cache(kKeptPlacements, kKeptPlacementBytes, [](const Placed& p) {
        return p.layout ? size_t(p.layout->fileBytes()) : p.refusal.size();
    });
    return cache;
}

}  // namespace

std::shared_ptr<const ProbeLayout> keptPlacement(const SceneDescription& scene, size_t volume, const Heightfield& hf) {
    const ProbeVolumeSettings& settings = scene.probeVolumes.at(volume);
    const std::string key = sceneToJson(scene).at("probe_volumes").at(volume).dump();
    const auto placed = kept().get(hf.serial(), key, [&] {
        try {
            return Placed{placeProbes(settings, hf), {}};
        } catch (const PlacementError& e) {
            return Placed{std::nullopt, e.what()};
        }
    });
    if (!placed->layout) throw PlacementError(placed->refusal);
    return std::shared_ptr<const ProbeLayout>(placed, &*placed->layout);
}

size_t keptPlacements() { return kept().size(); }
size_t keptPlacementBytes() { return kept().bytes(); }

}  // namespace terralux
