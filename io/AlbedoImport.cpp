#include "AlbedoImport.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <vector>

#include <gdal_alg.h>
#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include "GdalSupport.h"

namespace terralux {
namespace {

using gdal::DatasetPtr;
using gdal::fmt;

[[noreturn]] void fail(const std::string& path, const std::string& what) {
    throw AlbedoMapError("terrain.albedo_map: " + path + ": " + what);
}

// Opens the map and checks its bands; the dataset and whether its samples are 16-bit.
DatasetPtr openMap(const std::string& path, bool& sixteenBit) {
    gdal::registerDriversOnce();
    if (path.empty()) throw AlbedoMapError("terrain.albedo_map: is empty; name an RGB raster");
    if (path.rfind("/vsi", 0) != 0) {
        std::error_code ec;
        if (!std::filesystem::exists(path, ec)) fail(path, "no such file");
        if (std::filesystem::is_directory(path, ec)) fail(path, "is a directory, not a raster");
    }
    DatasetPtr src(GDALOpenEx(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY, nullptr, nullptr, nullptr));
    if (!src) fail(path, gdal::withReason("not a raster GDAL can read"));
    auto* ds = static_cast<GDALDataset*>(src.get());
    const int bands = ds->GetRasterCount();
    if (bands != 3 && bands != 4)
        fail(path, "has " + std::to_string(bands) + " band" + (bands == 1 ? "" : "s") +
                       "; an albedo map needs 3 (RGB) or 4 (RGBA)");
    const GDALDataType type = ds->GetRasterBand(1)->GetRasterDataType();
    for (int b = 2; b <= bands; ++b)
        if (ds->GetRasterBand(b)->GetRasterDataType() != type)
            fail(path, "bands differ in data type; an albedo map's bands must all be 8 or all 16 bits");
    if (type != GDT_Byte && type != GDT_UInt16)
        fail(path, std::string("has ") + GDALGetDataTypeName(type) +
                       " samples; an albedo map must be 8 or 16 bits (Byte or UInt16)");
    if (ds->GetRasterXSize() < 1 || ds->GetRasterYSize() < 1) fail(path, "has no pixels");
    if (const std::string block = gdal::oversizedBlock(src.get()); !block.empty()) fail(path, block);
    sixteenBit = type == GDT_UInt16;
    return src;
}

bool hasCrs(GDALDataset* ds) {
    const OGRSpatialReference* s = ds->GetSpatialRef();
    return s && !s->IsEmpty();
}

}  // namespace

void checkAlbedoMap(const std::string& path) {
    gdal::QuietErrors quiet;
    bool sixteenBit = false;
    openMap(path, sixteenBit);
}

SurfaceAlbedo importAlbedoMap(const std::string& path, const Heightfield& terrain,
                              const std::string& demName, glm::vec3 fallback, int maxSide) {
    gdal::QuietErrors quiet;
    bool sixteenBit = false;
    DatasetPtr src = openMap(path, sixteenBit);
    auto* ds = static_cast<GDALDataset*>(src.get());
    const int bands = ds->GetRasterCount();
    if (terrain.width() < 2 || terrain.depth() < 2)
        fail(path, "the DEM " + demName + " has no area to drape a map over");

    const std::string& demWkt = terrain.geo.crsWkt;
    const bool demCrs = !demWkt.empty(), mapCrs = hasCrs(ds);
    if (demCrs != mapCrs)
        fail(path, std::string(mapCrs ? "has a CRS but the DEM " + demName + " has none"
                                      : "has no CRS but the DEM " + demName + " has one") +
                       "; give both a CRS (the map is reprojected onto the DEM) or neither (the map is stretched over the DEM)");

    // The footprint in the coordinates the warp works in: the DEM's CRS units, or metres of a
    // local frame when neither has a CRS. Engine X is east and Z south of the footprint centre.
    double unit = 1.0;
    if (demCrs) {
        OGRSpatialReference srs;
        if (srs.importFromWkt(demWkt.c_str()) != OGRERR_NONE)
            fail(path, "the DEM " + demName + " has a CRS GDAL cannot read back");
        if (srs.IsProjected()) unit = srs.GetLinearUnits();
        if (!(unit > 0.0)) unit = 1.0;
    }
    const double west = (terrain.geo.easting + terrain.minX()) / unit;
    const double east = (terrain.geo.easting + terrain.maxX()) / unit;
    const double north = (terrain.geo.northing - terrain.minZ()) / unit;
    const double south = (terrain.geo.northing - terrain.maxZ()) / unit;

    DatasetPtr placed;  // the map with the georeferencing the warp reads
    GDALDatasetH warpSource = src.get();
    double mapPixel = 0.0;  // the map's pixel in the warp's units (the finer axis)
    std::string why;
    if (!mapCrs) {
        // Stretched over the DEM raster's cells: its outer edges are half a cell beyond the
        // vertex footprint.
        const double hx = 0.5 * terrain.cellSizeX() / unit, hz = 0.5 * terrain.cellSizeZ() / unit;
        placed = gdal::translate(src.get(),
                                 {"-of", "VRT", "-a_ullr", fmt(west - hx), fmt(north + hz),
                                  fmt(east + hx), fmt(south - hz)},
                                 why);
        if (!placed) fail(path, why);
        warpSource = placed.get();
        mapPixel = std::min((east - west + 2 * hx) / ds->GetRasterXSize(),
                            (north - south + 2 * hz) / ds->GetRasterYSize());
    } else {
        void* transformer =
            GDALCreateGenImgProjTransformer(src.get(), nullptr, nullptr, demWkt.c_str(), FALSE, 0.0, 0);
        double gt[6];
        int w = 0, h = 0;
        const bool ok = transformer &&
                        GDALSuggestedWarpOutput(src.get(), GDALGenImgProjTransform, transformer, gt, &w, &h) == CE_None;
        if (transformer) GDALDestroyGenImgProjTransformer(transformer);
        if (!ok) fail(path, gdal::withReason("cannot be reprojected into the CRS of the DEM " + demName));
        mapPixel = std::min(std::abs(gt[1]), std::abs(gt[5]));
    }
    if (!(mapPixel > 0.0) || !std::isfinite(mapPixel)) fail(path, "has no usable pixel size");

    // The map's own resolution over the footprint, texel centres on its corners, capped.
    const double spanX = east - west, spanZ = north - south;
    double w = std::floor(spanX / mapPixel) + 1.0, h = std::floor(spanZ / mapPixel) + 1.0;
    const double shrink = std::min(1.0, double(maxSide) / std::max(w, h));
    const int width = std::clamp(int(std::lround(w * shrink)), 2, std::max(maxSide, 2));
    const int height = std::clamp(int(std::lround(h * shrink)), 2, std::max(maxSide, 2));
    const double px = spanX / (width - 1), pz = spanZ / (height - 1);
    // Coarser than the map: average what falls in a texel instead of sampling between pixels.
    const bool coarser = px > 1.5 * mapPixel || pz > 1.5 * mapPixel;

    std::vector<std::string> args = {"-of", "MEM", "-te", fmt(west - 0.5 * px), fmt(south - 0.5 * pz),
                                     fmt(east + 0.5 * px), fmt(north + 0.5 * pz),
                                     "-ts", std::to_string(width), std::to_string(height),
                                     "-r", coarser ? "average" : "bilinear", "-dstalpha"};
    if (demCrs) args.insert(args.end(), {"-t_srs", demWkt});
    if (bands == 4) args.push_back("-srcalpha");
    DatasetPtr warped = gdal::warp(warpSource, args, why);
    if (!warped) fail(path, why);
    auto* out = static_cast<GDALDataset*>(warped.get());
    if (out->GetRasterCount() != 4 || out->GetRasterXSize() != width || out->GetRasterYSize() != height)
        fail(path, "the reprojected map is not the " + std::to_string(width) + " x " +
                       std::to_string(height) + " RGBA grid asked for");

    const size_t n = size_t(width) * size_t(height);
    std::vector<uint16_t> samples[4];
    for (int b = 0; b < 4; ++b) {
        samples[b].resize(n);
        if (out->GetRasterBand(b + 1)->RasterIO(GF_Read, 0, 0, width, height, samples[b].data(), width,
                                                height, GDT_UInt16, 0, 0, nullptr) != CE_None)
            fail(path, gdal::withReason("cannot read band " + std::to_string(b + 1)));
    }

    // sRGB decoding by table: every sample value, decoded once.
    const int levels = sixteenBit ? 65536 : 256;
    std::vector<float> decode(static_cast<size_t>(levels));
    for (int v = 0; v < levels; ++v) decode[size_t(v)] = srgbToLinear(float(v) / float(levels - 1));

    SurfaceAlbedo field;
    field.resize(width, height);
    field.fallback = fallback;
    size_t covered = 0;
    for (size_t i = 0; i < n; ++i) {
        const float a = std::min(float(samples[3][i]) / float(levels - 1), 1.0f);
        covered += samples[3][i] > 0;
        const glm::vec3 map(decode[std::min<size_t>(samples[0][i], size_t(levels - 1))],
                            decode[std::min<size_t>(samples[1][i], size_t(levels - 1))],
                            decode[std::min<size_t>(samples[2][i], size_t(levels - 1))]);
        field.setTexel(i, a >= 1.0f ? map : a * map + (1.0f - a) * fallback);
    }
    if (covered == 0)
        fail(path, "does not overlap the DEM " + demName + " (or holds only nodata there)");
    return field;
}

}  // namespace terralux
