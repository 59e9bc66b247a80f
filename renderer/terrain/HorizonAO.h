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

}  // namespace terralux
