#pragma once
// Horizon-based ambient occlusion of the heightfield (docs/lighting.md, "Horizon ambient
// occlusion"): per vertex, the horizon elevation in a set of azimuths, integrated over the
// hemisphere of the vertex normal in closed form.
//
// Horizons come from the line sweep of Timonen and Westerholm, "Scalable Height Field
// Self-Shadowing" (Eurographics 2010): parallel lines cross the grid in each azimuth and the upper
// convex hull of the profile already walked gives every sample's horizon in O(1) amortised. The
// slice integral is the one of Jimenez et al., "Practical Realtime Strategies for Accurate
// Indirect Occlusion" (GTAO, 2016), with the cosine of the vertex normal.
//
// Only terrain inside the footprint occludes: the skirt of Heightfield.h is ignored.

#include <functional>
#include <vector>

#include <glm/vec3.hpp>

#include "terrain/Heightfield.h"

namespace terralux {

struct HorizonAoSettings {
    int directions = 32;        // azimuths swept, 8..64
    double maxDistance = 0.0;   // metres a horizon search reaches; 0 = unbounded
};

// Cosine-weighted sky visibility at every vertex (row-major, width*depth, in [0, 1]): the share of
// a uniform sky's irradiance that reaches the surface with the vertex normal. progress(fraction)
// is called now and then from the calling thread or workers; when it returns false the
// computation stops and the function returns an empty vector. Throws std::invalid_argument for
// settings out of range.
std::vector<float> horizonSkyVisibility(const Heightfield& terrain, const HorizonAoSettings& settings,
                                        const std::function<bool(double)>& progress = {});

// Same measure at one arbitrary point (x, z) on the surface, for tests and the benchmark. It uses
// the triangle normal there (Heightfield::surfaceNormal) and searches the horizon from the point
// itself; the field above uses the vertex normal and the sweep's lines. Throws
// std::invalid_argument for a point outside the footprint or settings out of range.
float horizonSkyVisibilityAt(const Heightfield& terrain, const HorizonAoSettings& settings, float x, float z);

// The share of the sun's disc (centre `elevation`, radius `angularRadius`, radians) above a
// horizon at elevation `horizon`: the circular segment's area over the disc's.
float sunDiscAboveHorizon(float horizon, float elevation, float angularRadius);

// The share of the sun's disc the terrain leaves visible at every vertex (row-major, width ×
// depth): the horizon in the sun's azimuth from one line sweep (the sweep above, Timonen and
// Westerholm 2010), the disc's part above it (sunDiscAboveHorizon). Only the terrain's occlusion:
// a surface turned from the sun is not darkened here. `skirt`: the surface continues past the
// border at the nearest border point, as the tracer's skirt does. toSun: unit, toward the sun.
std::vector<float> sunHorizonVisibility(const Heightfield& terrain, const glm::vec3& toSun, float angularRadius,
                                        bool skirt);

}  // namespace terralux
