#include "scene/ShadowCascades.h"

#include <algorithm>
#include <cmath>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "ShaderMath.h"

namespace terralux {

std::vector<double> practicalSplits(double n, double f, int cascades, double lambda) {
    std::vector<double> ends;
    const int count = std::max(cascades, 1);
    n = std::max(n, 1e-6);
    f = std::max(f, n);
    for (int i = 1; i <= count; ++i) {
        const double s = double(i) / double(count);
        const double logSplit = n * std::pow(f / n, s);
        const double uniSplit = n + (f - n) * s;
        ends.push_back(i == count ? f : lambda * logSplit + (1.0 - lambda) * uniSplit);
    }
    return ends;
}

namespace {

std::vector<glm::vec3> boxCorners(const glm::vec3& lo, const glm::vec3& hi) {
    std::vector<glm::vec3> c;
    for (int i = 0; i < 8; ++i)
        c.push_back({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
    return c;
}

// Camera forward axis (unit) of the orbit camera.
glm::vec3 forwardOf(const OrbitCamera& camera) {
    return glm::normalize(camera.target - camera.position());
}

}  // namespace

CascadeRange cascadeRange(const ShadowSettings& s, const OrbitCamera& camera, float aspect,
                          const glm::vec3& lo, const glm::vec3& hi) {
    const glm::vec3 eye = camera.position(), fwd = forwardOf(camera);
    const float extent = std::max({hi.x - lo.x, hi.z - lo.z, hi.y - lo.y, 1.0f});
    const OrbitCamera::Planes planes = camera.planes(extent);
    (void)aspect;
    // View depth of the terrain box: its corners bound both ends (depth is linear, so a box's
    // extremes are at corners); the near plane bounds the near end when the eye is inside.
    double farthest = 0.0, nearest = INFINITY;
    for (const glm::vec3& c : boxCorners(lo, hi)) {
        const double d = glm::dot(c - eye, fwd);
        farthest = std::max(farthest, d);
        nearest = std::min(nearest, d);
    }
    CascadeRange r;
    r.nearDistance = std::clamp(nearest, double(planes.nearPlane), double(planes.farPlane));
    r.farDistance = std::clamp(s.maxDistance ? *s.maxDistance : farthest, r.nearDistance + 1e-3,
                               double(planes.farPlane));
    r.fadesOut = r.farDistance < farthest;
    const int n = std::clamp(s.cascades, 1, 4);
    if (s.splitMode == SplitMode::Manual && s.splits && int(s.splits->size()) == n - 1) {
        double last = r.nearDistance;
        for (double d : *s.splits) {
            // Keep every cascade non-empty when the range is shorter than the authored splits.
            last = std::clamp(d, last + 1e-3, r.farDistance - 1e-3 * double(n - int(r.ends.size())));
            r.ends.push_back(last);
        }
        r.ends.push_back(r.farDistance);
    } else {
        r.ends = practicalSplits(r.nearDistance, r.farDistance, n, s.splitLambda);
    }
    return r;
}

std::vector<double> fitManualSplits(const std::vector<double>& authored, int cascades,
                                    const CascadeRange& practical, std::optional<double> maxDistance) {
    const size_t n = size_t(std::clamp(cascades, 1, 4) - 1);
    const double limit = maxDistance ? *maxDistance : INFINITY;
    std::vector<double> out;
    for (double d : authored) {
        if (out.size() == n || !(d > (out.empty() ? 0.0 : out.back())) || !(d < limit)) break;
        out.push_back(d);
    }
    const size_t kept = out.size();
    for (size_t i = 0; i + 1 < practical.ends.size() && out.size() < n; ++i) {
        const double d = practical.ends[i];
        if (d > (out.empty() ? 0.0 : out.back()) && d < limit) out.push_back(d);
    }
    if (out.size() < n) {
        // Authored splits beyond the practical ones: share what is left of the range evenly.
        const double from = out.empty() ? practical.nearDistance : out.back();
        double to = std::min(practical.farDistance, limit);
        if (!(to > from)) to = std::isfinite(limit) ? limit : 2.0 * from + 1.0;
        const size_t missing = n - out.size();
        for (size_t k = 1; k <= missing; ++k) out.push_back(from + (to - from) * double(k) / double(missing + 1));
    }
    // The dock edits splits in whole metres: added ones start there unless rounding would
    // reorder them or reach the end of the range.
    for (size_t i = kept; i < out.size(); ++i) {
        const double r = std::round(out[i]);
        const double next = i + 1 < out.size() ? out[i + 1] : std::min(limit, practical.farDistance);
        if (r > (i ? out[i - 1] : 0.0) && r < next) out[i] = r;
    }
    return out;
}

std::vector<Cascade> fitCascades(const CascadeRange& range, const OrbitCamera& camera, float aspect,
                                 const glm::vec3& sunDirection, int resolution, const glm::vec3& lo,
                                 const glm::vec3& hi) {
    const glm::vec3 eye = camera.position(), fwd = forwardOf(camera);
    const glm::vec3 sun = glm::normalize(sunDirection);
    // A fixed light basis (not the camera's): the snap grid must stay put while the camera turns.
    const glm::vec3 up = std::abs(sun.y) > 0.999f ? glm::vec3(0.0f, 0.0f, 1.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
    const glm::mat4 lightRotation = glm::lookAt(glm::vec3(0.0f), -sun, up);
    // Squared slope of the frustum's corner rays: a point at view depth d is d·k off axis.
    const float t = std::tan(glm::radians(0.5f * camera.fovDeg));
    const double k2 = double(t) * t * (1.0 + double(aspect) * aspect);
    // Light-space depth (along −sun) of the terrain box.
    float zMin = INFINITY, zMax = -INFINITY;
    for (const glm::vec3& c : boxCorners(lo, hi)) {
        const float z = -(lightRotation * glm::vec4(c, 1.0f)).z;
        zMin = std::min(zMin, z);
        zMax = std::max(zMax, z);
    }
    std::vector<Cascade> out;
    double a = range.nearDistance;
    for (double b : range.ends) {
        Cascade c;
        c.nearDistance = a;
        c.farDistance = b;
        // Smallest sphere around the slice's 8 corners: its centre on the axis, equidistant from
        // the near and far corner rings, or at the far plane when the far ring alone decides.
        const double zc = std::min(b, 0.5 * (a + b) * (1.0 + k2));
        const double radius = std::sqrt((b - zc) * (b - zc) + b * b * k2);
        // Rounded up to a 1/64 step of itself so float noise cannot move the texel grid.
        const double step = std::exp2(std::ceil(std::log2(radius)) - 6.0);
        c.radius = float(std::ceil(radius / step) * step);
        c.texelSize = 2.0f * c.radius / float(resolution);
        const glm::vec3 centre = eye + fwd * float(zc);
        glm::vec3 lc = glm::vec3(lightRotation * glm::vec4(centre, 1.0f));
        lc.x = std::floor(lc.x / c.texelSize) * c.texelSize;
        lc.y = std::floor(lc.y / c.texelSize) * c.texelSize;
        // Depth: the whole terrain toward the sun, with a margin of a few texels.
        const float margin = 4.0f * c.texelSize + 1.0f;
        const float zNear = zMin - margin, zFar = zMax + margin;
        c.depthRange = zFar - zNear;
        const glm::mat4 proj = glm::orthoRH_ZO(lc.x - c.radius, lc.x + c.radius, lc.y - c.radius,
                                               lc.y + c.radius, zNear, zFar);
        c.lightViewProj = proj * lightRotation;
        out.push_back(c);
        a = b;
    }
    return out;
}

HorizonMapInfo horizonMapOf(int demWidth, int demDepth, float spanX, float spanZ, int maxSide) {
    HorizonMapInfo m;
    m.width = std::min(demWidth, maxSide);
    m.height = std::min(demDepth, maxSide);
    m.cell = std::max(spanX / float(std::max(m.width - 1, 1)), spanZ / float(std::max(m.height - 1, 1)));
    return m;
}

int horizonFirstCascade(const std::vector<Cascade>& cascades, float sunElevationSin, const HorizonMapInfo& map) {
    if (map.width <= 0) return int(cascades.size());
    const float sinE = std::clamp(sunElevationSin, -1.0f, 1.0f);
    const float tanE = sinE / std::max(std::sqrt(1.0f - sinE * sinE), 1e-6f);
    for (size_t i = 0; i < cascades.size(); ++i)
        if (glsl::shadowTakesHorizon(cascades[i].texelSize, tanE, map.cell)) return int(i);
    return int(cascades.size());
}

}  // namespace terralux
