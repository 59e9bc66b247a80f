#pragma once
// The terrain's albedo over its footprint: what the bake reflects light with, what the viewport
// draws and what the glTF export writes as the terrain's base colour texture (docs/lighting.md,
// "Terrain albedo"). Pure CPU: the map import that fills it from a raster lives in io/.

#include <vector>

#include <glm/vec3.hpp>

#include "scene/SceneDescription.h"
#include "terrain/Heightfield.h"

namespace terralux {

// Largest albedo field side, for maps and ramps alike (a GPU texture and a PNG of it stay sane).
inline constexpr int kMaxSurfaceAlbedoSide = 4096;

// Linear albedo over the terrain footprint. Texel centres span the footprint corner to corner:
// texel (i, j) lies at x = minX + i (maxX − minX)/(width − 1), z = minZ + j (maxZ − minZ)/(height − 1)
// (row 0 north, like the heightfield). Empty (width 0) means the constant albedo everywhere.
struct SurfaceAlbedo {
    int width = 0, height = 0;
    std::vector<glm::vec3> linear;  // width*height, row-major
    glm::vec3 fallback{0.3f};       // the constant albedo (terrain.albedo)

    bool empty() const { return width <= 0 || height <= 0; }
    // Bilinear between texel centres, clamped to the footprint (the skirt takes its border's
    // albedo); the fallback when empty.
    glm::vec3 at(const Heightfield& terrain, float x, float z) const;
    // Per channel, the largest albedo anywhere on the terrain (the fallback when empty).
    glm::vec3 maximum() const;
};

// The ramp at every vertex of the heightfield: a field of the heightfield's own size, up to
// kMaxSurfaceAlbedoSide a side (a larger heightfield gets that many texels, each evaluated at the
// vertex nearest its centre). Elevation is (vertex height + geo.height) / verticalScale, the DEM's
// own metres whatever exaggeration the terrain is lit with; slope is the angle of vertexNormal
// from vertical, as lit.
SurfaceAlbedo rampAlbedo(const Heightfield& terrain, const AlbedoRampSettings& ramp,
                         double verticalScale, glm::vec3 fallback);

// The ramp's colour at one elevation (metres) and slope (degrees).
glm::vec3 rampColor(const AlbedoRampSettings& ramp, double elevation, double slopeDeg);

// The exact sRGB electro-optical transfer function (IEC 61966-2-1): encoded [0, 1] to linear.
float srgbToLinear(float encoded);
// Its inverse, linear [0, 1] to encoded.
float linearToSrgb(float linear);

}  // namespace terralux
