#pragma once
// The lighting the bake tests and benchmarks share: a uniform sky (0.6, 0.75, 1.0), a sun of
// illuminance (3, 2.88, 2.7) from azimuth 135° at 35° with the real sun's 0.27° radius, albedo 0.3.

#include <numbers>

#include "bake/DiffuseBake.h"
#include "bake/HeightfieldTracer.h"
#include "bake/Sky.h"

namespace terralux::test {

inline BakeLighting skyAndSun(const HeightfieldTracer& tracer) {
    BakeLighting L;
    L.tracer = &tracer;
    L.sky = Sky::uniform(glm::vec3(0.6f, 0.75f, 1.0f));
    L.sun.direction = sunDirection(135.0, 35.0);
    L.sun.illuminance = glm::vec3(3.0f, 2.88f, 2.7f);
    L.sun.angularRadius = 0.27f * std::numbers::pi_v<float> / 180.0f;
    L.albedo = glm::vec3(0.3f);
    return L;
}

}  // namespace terralux::test
