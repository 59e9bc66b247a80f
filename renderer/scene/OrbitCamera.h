#pragma once
// The orbit camera of the viewport and `terralux --render`: it circles a target at a radius,
// standing at an azimuth (clockwise from north) and an elevation.

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "scene/SceneDescription.h"
#include "terrain/Heightfield.h"

namespace terralux {

struct OrbitCamera {
    glm::vec3 target{0.0f};
    float radius = 1.0f;
    float azimuthDeg = 210.0f;
    float elevationDeg = 35.0f;
    float fovDeg = 45.0f;

    // Fills what the settings leave unset from the terrain: target at the footprint centre and
    // mean height, radius framing the whole footprint.
    static OrbitCamera fromSettings(const CameraSettings& s, const Heightfield& hf);
    glm::vec3 position() const;
    // Where the light propagation volumes are placed from (docs/lighting.md, "Cascades"): a viewer
    // standing at the target, looking along this camera's view direction. The orbit camera hovers
    // far above the ground, where cascades around it would hold only air.
    glm::vec3 lpvEye() const { return target; }
    glm::vec3 lpvViewDirection() const { return target - position(); }
    // Near and far planes fitted to the radius and the scene's `extent` (its largest side).
    struct Planes {
        float nearPlane = 0.05f, farPlane = 1.0f;
    };
    Planes planes(float extent) const;
    // Vulkan clip space (y down, depth 0..1), near/far from planes().
    glm::mat4 viewProjection(float aspect, float extent) const;
    // The camera mirrored in the plane y = level (the planar reflection's view): its position,
    // and its view-projection with the near plane replaced by the water plane, so that nothing
    // below the water reaches the reflection (Lengyel 2005, "Oblique View Frustum Depth
    // Projection and Clipping", JGT 10(2), for Vulkan's 0..1 depth).
    glm::vec3 reflectedPosition(float level) const;
    glm::mat4 reflectedViewProjection(float aspect, float extent, float level) const;
};

}  // namespace terralux
