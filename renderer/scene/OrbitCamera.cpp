#include "scene/OrbitCamera.h"

#include <algorithm>
#include <cmath>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/matrix.hpp>
#include <glm/trigonometric.hpp>

namespace terralux {

OrbitCamera OrbitCamera::fromSettings(const CameraSettings& s, const Heightfield& hf) {
    OrbitCamera c;
    c.target = s.target ? *s.target : glm::vec3(0.0f, hf.meanHeight(), 0.0f);
    c.fovDeg = float(s.fovDeg);
    c.azimuthDeg = float(s.azimuthDeg);
    c.elevationDeg = float(s.elevationDeg);
    if (s.radius) {
        c.radius = float(*s.radius);
    } else {
        const float dx = hf.maxX() - hf.minX(), dz = hf.maxZ() - hf.minZ();
        const float dy = hf.maxHeight() - hf.minHeight();
        const float halfDiagonal = 0.5f * std::sqrt(dx * dx + dz * dz + dy * dy);
        c.radius = std::max(halfDiagonal / std::tan(glm::radians(0.5f * c.fovDeg)) * 0.85f, 1.0f);
    }
    return c;
}

glm::vec3 OrbitCamera::position() const {
    const float az = glm::radians(azimuthDeg), el = glm::radians(elevationDeg);
    return target + radius * glm::vec3(std::sin(az) * std::cos(el), std::sin(el),
                                       -std::cos(az) * std::cos(el));
}

OrbitCamera::Planes OrbitCamera::planes(float extent) const {
    Planes p;
    p.farPlane = radius + 2.0f * extent;
    p.nearPlane = std::max(p.farPlane * 1e-5f, 0.05f);
    return p;
}

namespace {

// Reversed Z: depth 1 at the near plane, 0 at the far one (the planes swapped in the 0..1
// perspective), so float depth is about as fine far away as near (Reed 2015, "Depth Precision
// Visualized").
glm::mat4 projection(const OrbitCamera& c, float aspect, float extent) {
    const OrbitCamera::Planes p = c.planes(extent);
    glm::mat4 proj = glm::perspectiveRH_ZO(glm::radians(c.fovDeg), aspect, p.farPlane, p.nearPlane);
    proj[1][1] *= -1.0f;  // Vulkan's clip-space y points down
    return proj;
}

float sign(float x) { return x > 0.0f ? 1.0f : x < 0.0f ? -1.0f : 0.0f; }

}  // namespace

glm::mat4 OrbitCamera::viewProjection(float aspect, float extent) const {
    const glm::mat4 view = glm::lookAt(position(), target, glm::vec3(0.0f, 1.0f, 0.0f));
    return projection(*this, aspect, extent) * view;
}

glm::vec3 OrbitCamera::reflectedPosition(float level) const {
    const glm::vec3 p = position();
    return {p.x, 2.0f * level - p.y, p.z};
}

glm::mat4 OrbitCamera::reflectedViewProjection(float aspect, float extent, float level) const {
    // The mirror y -> 2·level − y, then the camera's own view: the reflected scene as the camera
    // sees it in the water (winding flips; no pass culls faces).
    glm::mat4 mirror(1.0f);
    mirror[1][1] = -1.0f;
    mirror[3][1] = 2.0f * level;
    const glm::mat4 view = glm::lookAt(position(), target, glm::vec3(0.0f, 1.0f, 0.0f)) * mirror;
    glm::mat4 proj = projection(*this, aspect, extent);
    // The water plane y = level in the mirrored camera's space, facing the kept (upper) side: in
    // world space (0, 1, 0, −level); planes transform by the inverse transpose.
    const glm::vec4 c = glm::transpose(glm::inverse(view)) * glm::vec4(0.0f, 1.0f, 0.0f, -level);
    // Lengyel: the corner of the view frustum opposite the plane, q = P⁻¹ (±1, ±1, 0, 1) on the
    // far plane (depth 0 in reversed Z). The near plane w − z >= 0 becomes a·c >= 0: the depth
    // row is w − a·c, with a such that the far plane (depth row · v = 0) still passes through q.
    // Vulkan's flipped y maps the sign of c.y through P[1][1].
    const glm::vec4 qClip(sign(c.x) * sign(proj[0][0]), sign(c.y) * sign(proj[1][1]), 0.0f, 1.0f);
    const glm::vec4 q = glm::inverse(proj) * qClip;
    const glm::vec4 wRow(proj[0][3], proj[1][3], proj[2][3], proj[3][3]);
    const float cq = glm::dot(c, q);
    if (std::abs(cq) > 1e-12f) {
        const glm::vec4 depthRow = wRow - c * (glm::dot(wRow, q) / cq);
        for (int col = 0; col < 4; ++col) proj[col][2] = depthRow[col];
    }
    return proj * view;
}

}  // namespace terralux
