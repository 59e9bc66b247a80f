#pragma once
// The terrain surface as the viewport samples it, per texel rather than per mesh vertex: the mesh
// of a large DEM is thinned (TerrainRenderer's vertex budget), the surface maps are not.
//
// Texel centres span the footprint corner to corner: texel (i, j) of level 0 lies at
// x = minX + i (maxX − minX)/(width − 1), z = minZ + j (maxZ − minZ)/(height − 1), row 0 north. A
// shader reaches it at uv = (t (size − 1) + 0.5) / size, t in [0, 1] across the footprint.
//
// The normal is stored as the mean of the unit normals under a texel, not renormalised: its
// shortening is the spread of the normals it stands for, which survives every mip level and the
// hardware's filtering between them (Toksvig 2005, "Mipmapping normal maps").

#include <cstdint>
#include <vector>

#include <glm/vec4.hpp>

#include "terrain/Heightfield.h"

namespace terralux {

// Level 0 holds at most this many texels a side; a larger DEM averages several vertices a texel.
inline constexpr int kMaxSurfaceTexels = 4096;

struct SurfaceMaps {
    int width = 0, height = 0;  // level 0
    // Per level, row-major: xyz the mean unit normal, w the sky visibility (1 without AO).
    std::vector<std::vector<glm::vec4>> normalAo;
    // Level 0 only: the share of filled (nodata) DEM cells under each texel, 0..255.
    std::vector<uint8_t> filled;
};

// Builds the maps of `terrain`. `ao`: per vertex (width × depth, row-major, as
// horizonSkyVisibility returns), or empty for none. `maxTexels` caps the level-0 side.
SurfaceMaps buildSurfaceMaps(const Heightfield& terrain, const std::vector<float>& ao,
                             int maxTexels = kMaxSurfaceTexels);

// Variance of the normals behind a mean normal of length `meanLength` (Toksvig 2005, eq. 3 with a
// Gaussian slope distribution): σ² = (1 − |N̄|) / |N̄|; 0 for a unit normal.
float toksvigVariance(float meanLength);

// GGX roughness widened by a normal variance, keeping r' <= 1: r' = sqrt(r² + σ² (1 − r²)).
// Roughness² is the slope variance of the microfacets (Olano & Baker 2010, LEAN mapping), and
// independent variances add; the (1 − r²) factor is the share of the lobe still to widen.
float widenedRoughness(float roughness, float variance);

}  // namespace terralux
