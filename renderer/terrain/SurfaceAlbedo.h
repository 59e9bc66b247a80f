#pragma once
// The terrain's albedo over its footprint: what the bake reflects light with, what the viewport
// draws and what the glTF export writes as the terrain's base colour texture (docs/lighting.md,
// "Terrain albedo"). Pure CPU: the map import that fills it from a raster lives in io/.

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "scene/SceneDescription.h"
#include "terrain/Heightfield.h"

namespace terralux {

// Largest albedo field side, for maps and ramps alike (a GPU texture and a PNG of it stay sane).
inline constexpr int kMaxSurfaceAlbedoSide = 4096;

// Albedo over the terrain footprint. Texel centres span the footprint corner to corner:
// texel (i, j) lies at x = minX + i (maxX − minX)/(width − 1), z = minZ + j (maxZ − minZ)/(height − 1)
// (row 0 north, like the heightfield). Empty (width 0) means the constant albedo everywhere.
//
// Texels are kept sRGB-encoded in 8 bits, 3 bytes each: the precision of the viewport's albedo
// texture and of the glTF's PNG, so the bake reflects light with exactly the albedo the engine
// is given, at a quarter of the memory of linear floats (a 1000² field: 3 MB instead of 12 MB).
// Rounding to a code moves an albedo by at most 0.0045 (at 1), 0.7 % at 0.3 (docs/lighting.md,
// "Terrain albedo").
struct SurfaceAlbedo {
    int width = 0, height = 0;
    std::vector<uint8_t> srgb;      // 3 × width × height, row-major, R G B
    glm::vec3 fallback{0.3f};       // the constant albedo (terrain.albedo)

    bool empty() const { return width <= 0 || height <= 0; }
    size_t texels() const { return srgb.size() / 3; }
    // Sizes the field and sets every texel to black.
    void resize(int w, int h);
    // Texel i (row-major) as linear albedo.
    glm::vec3 texel(size_t i) const;
    // Stores linear albedo, clamped to [0, 1], at texel i.
    void setTexel(size_t i, glm::vec3 linear);
    // Bilinear between texel centres, clamped to the footprint (the skirt takes its border's
    // albedo); the fallback when empty.
    glm::vec3 at(const Heightfield& terrain, float x, float z) const;
    // Per channel, the largest albedo anywhere on the terrain (the fallback when empty).
    glm::vec3 maximum() const;
};

// Linear [0, 1] to its nearest 8-bit sRGB code, and a code back to linear (exact to float).
uint8_t srgb8(float linear);
float linearOfSrgb8(uint8_t code);

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
