#include "render/features/Reflections.h"

#include <algorithm>

namespace terralux::features {

blocks::ReflectionBlock packReflections(const ReflectionResources& r, const RenderSettings& s) {
    blocks::ReflectionBlock block = r.grid;
    block.strength = std::clamp(s.reflectionStrength, 0.0f, 1.0f);
    return block;
}

}  // namespace terralux::features
