#pragma once
// terrain.albedo_map: an RGB(A) raster GDAL reads, reprojected and resampled onto the terrain's
// footprint as a SurfaceAlbedo (docs/lighting.md, "Terrain albedo").

#include <string>

#include <glm/vec3.hpp>

#include "EnvironmentImage.h"
#include "terrain/Heightfield.h"
#include "terrain/SurfaceAlbedo.h"

namespace terralux {

// A map that cannot be used: one line naming the setting, the file(s) and the rule.
class AlbedoMapError : public ImageError {
public:
    using ImageError::ImageError;
};

// Checks what the header says (exists, GDAL reads it, 3 or 4 bands of 8 or 16 bits) without
// reading pixels. Throws AlbedoMapError.
void checkAlbedoMap(const std::string& path);

// Reads `path` onto the footprint of `terrain` (whose DEM `demName` names in messages): the
// field's texel centres span the footprint corner to corner (SurfaceAlbedo), at the map's own
// resolution over it (the pixel size gdalwarp picks for the map in the DEM's CRS), at most
// `maxSide` texels a side. Co-registration:
//   - DEM and map both have a CRS: the map is warped into the DEM's CRS (bilinear, or area
//     average where the field is coarser than the map);
//   - neither has one: the map's whole raster is stretched over the DEM's raster (its
//     georeferencing, if any, is ignored);
//   - one has a CRS and the other not: an error naming both files.
// Bands 1-3 are sRGB-encoded red, green, blue (8 or 16 bits), decoded with the exact sRGB EOTF; a
// 4th band is alpha. Where the map has no data (outside it, its nodata, alpha 0) the field is
// `fallback`, blended by coverage at the map's edges. A map that covers no part of the footprint
// is an error naming both files.
SurfaceAlbedo importAlbedoMap(const std::string& path, const Heightfield& terrain,
                              const std::string& demName, glm::vec3 fallback,
                              int maxSide = kMaxSurfaceAlbedoSide);

}  // namespace terralux
