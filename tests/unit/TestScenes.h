#pragma once
// Scenes the bake tests and benchmarks share.

#include <functional>
#include <numbers>
#include <vector>

#include "bake/AdaptivePlacement.h"
#include "bake/DiffuseBake.h"
#include "bake/HeightfieldTracer.h"
#include "bake/Sky.h"

namespace terralux::test {

// A flat n × n terrain of `cell` metres at height h.
inline Heightfield flat(int n, double cell, float h) {
    return Heightfield(n, n, cell, cell, std::vector<float>(size_t(n) * n, h));
}

// A baker whose probes see a constant sky of radiance f(p): interpolation error is then the
// spatial error of the blend alone. `baked` (optional) counts the probes it bakes.
inline ProbeBaker fieldBaker(std::function<float(const glm::vec3&)> f, size_t* baked = nullptr) {
    return [f, baked](const std::vector<glm::vec3>& p, const std::vector<uint64_t>&) {
        ProbeBake b(p.size());
        for (size_t i = 0; i < p.size(); ++i) b.sh[i] = sh::projectConstant(glm::vec3(f(p[i])));
        b.rays = p.size();
        if (baked) *baked += p.size();
        return b;
    };
}

// A uniform sky (0.6, 0.75, 1.0), a sun of illuminance (3, 2.88, 2.7) from azimuth 135° at 35°
// with the real sun's 0.27° radius, albedo 0.3.
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
