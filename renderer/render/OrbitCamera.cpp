#include "render/OrbitCamera.h"

#include <algorithm>
#include <cmath>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/trigonometric.hpp>

namespace terralux {

OrbitCamera OrbitCamera::fromSettings(const CameraSettings& s, const Heightfield& hf) {
    OrbitCamera c;
    double sum = 0;
    for (float h : hf.heights()) sum += h;
    const float mean = float(sum / double(hf.heights().size()));
    c.target = s.target ? *s.target : glm::vec3(0.0f, mean, 0.0f);
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

glm::mat4 OrbitCamera::viewProjection(float aspect, float extent) const {
    const glm::mat4 view = glm::lookAt(position(), target, glm::vec3(0.0f, 1.0f, 0.0f));
    const Planes p = planes(extent);
    glm::mat4 proj = glm::perspectiveRH_ZO(glm::radians(fovDeg), aspect, p.nearPlane, p.farPlane);
    proj[1][1] *= -1.0f;  // Vulkan's clip-space y points down
    return proj * view;
}

}  // namespace terralux
