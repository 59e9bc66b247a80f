// DEM import against numbers computed independently with GDAL's own tools
// (tests/data/dem/expected.json, tests/data/dem/SOURCES.md).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <vector>

#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "DemImport.h"
#include "SampleTerrain.h"

using namespace terralux;
namespace fs = std::filesystem;

namespace {

const fs::path kData = fs::path(TERRALUX_TEST_DATA) / "dem";
const fs::path kShared = fs::path(TERRALUX_SHARED_DATA) / "dem";

const nlohmann::json& expected() {
    static const nlohmann::json j = [] {
        std::ifstream in(kData / "expected.json");
        return nlohmann::json::parse(in);
    }();
    return j;
}

std::string importError(const std::string& path, DemImportOptions o = {}) {
    try {
        importDem(path, o);
    } catch (const DemError& e) {
        return e.what();
    }
    return "";
}

double meanHeight(const Heightfield& hf) {
    double s = 0;
    for (float h : hf.heights()) s += h;
    return s / double(hf.heights().size());
}

// Heights on filled cells must come from their neighbours: inside the valid range.
void expectFilledWithinValidRange(const Heightfield& hf, double lo, double hi) {
    ASSERT_EQ(hf.nodataMask().size(), hf.heights().size());
    for (size_t i = 0; i < hf.heights().size(); ++i) {
        if (!hf.nodataMask()[i]) continue;
        EXPECT_GE(hf.heights()[i], lo - 1.0) << "cell " << i;
        EXPECT_LE(hf.heights()[i], hi + 1.0) << "cell " << i;
    }
}

}  // namespace

TEST(DemImport, ProjectedGeoTiff) {
    const auto& e = expected()["bigtujunga_utm11_crop.tif"];
    const auto r = importDem((kData / "bigtujunga_utm11_crop.tif").string());
    const Heightfield& hf = r.heightfield;
    EXPECT_EQ(r.source.driver, "GTiff");
    EXPECT_EQ(r.source.sourceEpsg, 32611);
    EXPECT_FALSE(r.source.reprojected);
    EXPECT_EQ(hf.width(), e["cols"].get<int>());
    EXPECT_EQ(hf.depth(), e["rows"].get<int>());
    EXPECT_DOUBLE_EQ(hf.cellSizeX(), 30.0);
    EXPECT_DOUBLE_EQ(hf.cellSizeZ(), 30.0);
    EXPECT_FLOAT_EQ(hf.minHeight(), e["min"].get<float>());
    EXPECT_FLOAT_EQ(hf.maxHeight(), e["max"].get<float>());
    EXPECT_NEAR(meanHeight(hf), e["mean"].get<double>(), 1e-3);
    EXPECT_EQ(hf.nodataCount(), 0u);
    // Vertices at pixel centres: the mesh spans (cols - 1) pixels, centred on the origin.
    EXPECT_FLOAT_EQ(hf.maxX() - hf.minX(), e["footprint_centres_x_m"].get<float>());
    EXPECT_FLOAT_EQ(hf.maxZ() - hf.minZ(), e["footprint_centres_y_m"].get<float>());
    EXPECT_FLOAT_EQ(hf.minX(), -hf.maxX());
    EXPECT_EQ(hf.geo.epsg, 32611);
    EXPECT_NEAR(hf.geo.easting, e["origin_x"].get<double>() + 96 * 30.0 / 2, 1e-6);
    EXPECT_NEAR(hf.geo.northing, e["origin_y"].get<double>() - 64 * 30.0 / 2, 1e-6);
}

TEST(DemImport, GeographicWithVoidsIsReprojectedToUtmAndFilled) {
    const auto& e = expected()["n42e001_voids_crop.tif"];
    const auto r = importDem((kData / "n42e001_voids_crop.tif").string());
    const Heightfield& hf = r.heightfield;
    EXPECT_TRUE(r.source.geographic);
    EXPECT_TRUE(r.source.reprojected);
    EXPECT_EQ(hf.geo.epsg, e["warped"]["utm_epsg"].get<int>());
    // gdalwarp's own choice of pixel size for this raster.
    EXPECT_NEAR(hf.cellSizeX(), e["warped"]["pixel_size_x"].get<double>(), 1e-3);
    EXPECT_NEAR(hf.cellSizeZ(), std::abs(e["warped"]["pixel_size_y"].get<double>()), 1e-3);
    // Trimmed to the part inside the source: never larger than gdalwarp's grid, rarely much smaller.
    EXPECT_LE(hf.width(), e["warped"]["cols"].get<int>());
    EXPECT_LE(hf.depth(), e["warped"]["rows"].get<int>());
    EXPECT_GE(hf.width(), e["warped"]["cols"].get<int>() - 6);
    EXPECT_GE(hf.depth(), e["warped"]["rows"].get<int>() - 6);
    // 135 source voids (26 holes) stay flagged; the corner wedges are trimmed, not counted.
    EXPECT_GT(hf.nodataCount(), 80u);
    EXPECT_LT(hf.nodataCount(), e["warped"]["nodata_count"].get<size_t>());
    EXPECT_GE(hf.minHeight(), e["min"].get<float>() - 1.0f);
    EXPECT_LE(hf.maxHeight(), e["max"].get<float>() + 1.0f);
    expectFilledWithinValidRange(hf, e["min"].get<double>(), e["max"].get<double>());
}

TEST(DemImport, GeographicSummitWithLargeHoles) {
    const auto& e = expected()["rainier_crop.tif"];
    const auto r = importDem((kData / "rainier_crop.tif").string());
    const Heightfield& hf = r.heightfield;
    EXPECT_EQ(hf.geo.epsg, 32610);
    EXPECT_NEAR(hf.cellSizeX(), e["warped"]["pixel_size_x"].get<double>(), 1e-3);
    // 23.6 % of the source is void; most of it survives the warp as flagged, filled cells.
    const double share = double(hf.nodataCount()) / double(hf.heights().size());
    EXPECT_GT(share, 0.15);
    EXPECT_LT(share, 0.35);
    expectFilledWithinValidRange(hf, e["min"].get<double>(), e["max"].get<double>());
    EXPECT_LE(hf.maxHeight(), e["max"].get<float>() + 1.0f);
}

TEST(DemImport, AsciiGridWithoutCrsIsTakenAsMetresWithAWarning) {
    const auto& e = expected()["orkhon_crop.asc"];
    const auto r = importDem((kData / "orkhon_crop.asc").string());
    const Heightfield& hf = r.heightfield;
    EXPECT_EQ(r.source.driver, "AAIGrid");
    EXPECT_EQ(hf.geo.epsg, 0);
    ASSERT_EQ(r.source.warnings.size(), 1u);
    EXPECT_NE(r.source.warnings[0].find("no CRS"), std::string::npos);
    EXPECT_EQ(hf.width(), e["cols"].get<int>());
    EXPECT_EQ(hf.depth(), e["rows"].get<int>());
    EXPECT_NEAR(hf.cellSizeX(), e["pixel_size_x"].get<double>(), 1e-6);
    EXPECT_NEAR(hf.minHeight(), e["min"].get<double>(), 1e-3);
    EXPECT_NEAR(hf.maxHeight(), e["max"].get<double>(), 1e-3);
    EXPECT_NEAR(meanHeight(hf), e["mean"].get<double>(), 1e-3);
}

TEST(DemImport, FrameMappingRowZeroIsNorthAtNegativeZ) {
    // A synthetic north-up raster whose value encodes its pixel: 1000 * row + col.
    GDALAllRegister();
    const fs::path tmp = fs::temp_directory_path() / "terralux_frame_test.tif";
    {
        GDALDriver* gtiff = GetGDALDriverManager()->GetDriverByName("GTiff");
        GDALDataset* ds = gtiff->Create(tmp.c_str(), 5, 3, 1, GDT_Float32, nullptr);
        double gt[6] = {500000.0, 10.0, 0.0, 4000000.0, 0.0, -20.0};
        ds->SetGeoTransform(gt);
        OGRSpatialReference srs;
        srs.importFromEPSG(32633);
        ds->SetSpatialRef(&srs);
        std::vector<float> v(15);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 5; ++c) v[r * 5 + c] = float(1000 * r + c);
        ASSERT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, 5, 3, v.data(), 5, 3, GDT_Float32,
                                                 0, 0, nullptr),
                  CE_None);
        GDALClose(ds);
    }
    const auto r = importDem(tmp.string());
    fs::remove(tmp);
    const Heightfield& hf = r.heightfield;
    EXPECT_EQ(hf.at(0, 0), 0.0f);     // north-west
    EXPECT_EQ(hf.at(4, 0), 4.0f);     // north-east: x grows east
    EXPECT_EQ(hf.at(0, 2), 2000.0f);  // south-west: z grows south
    EXPECT_FLOAT_EQ(hf.zOf(0), -20.0f);  // row 0 at the most negative z
    EXPECT_FLOAT_EQ(hf.xOf(0), -20.0f);
    EXPECT_DOUBLE_EQ(hf.cellSizeX(), 10.0);
    EXPECT_DOUBLE_EQ(hf.cellSizeZ(), 20.0);
    // The surface at the north-west corner is that vertex.
    EXPECT_FLOAT_EQ(hf.surfaceHeight(hf.xOf(0), hf.minZ()), 0.0f);
    EXPECT_DOUBLE_EQ(hf.geo.easting, 500025.0);
    EXPECT_DOUBLE_EQ(hf.geo.northing, 3999970.0);
}

namespace {

// A w x h Float32 GeoTIFF of `bands` bands in the given CRS and geotransform, band b's cell
// (col, row) holding value(b, col, row) (bands from 1).
fs::path writeTiff(const std::string& name, int epsg, const double (&gt)[6], int w, int h, int bands,
                   const std::function<float(int, int, int)>& value) {
    GDALAllRegister();
    const fs::path tmp = fs::temp_directory_path() / name;
    GDALDriver* gtiff = GetGDALDriverManager()->GetDriverByName("GTiff");
    GDALDataset* ds = gtiff->Create(tmp.c_str(), w, h, bands, GDT_Float32, nullptr);
    double g[6];
    std::copy(std::begin(gt), std::end(gt), g);
    ds->SetGeoTransform(g);
    OGRSpatialReference srs;
    srs.importFromEPSG(epsg);
    ds->SetSpatialRef(&srs);
    std::vector<float> v(size_t(w) * h);
    for (int b = 1; b <= bands; ++b) {
        for (int r = 0; r < h; ++r)
            for (int c = 0; c < w; ++c) v[size_t(r) * w + c] = value(b, c, r);
        EXPECT_EQ(ds->GetRasterBand(b)->RasterIO(GF_Write, 0, 0, w, h, v.data(), w, h, GDT_Float32, 0, 0, nullptr),
                  CE_None);
    }
    GDALClose(ds);
    return tmp;
}

// The same with one band, every cell 100 m.
fs::path writeFlatTiff(const std::string& name, int epsg, const double (&gt)[6], int w = 4, int h = 3) {
    return writeTiff(name, epsg, gt, w, h, 1, [](int, int, int) { return 100.0f; });
}

}  // namespace

// The heights are the first band, whichever way the import goes: read as it is, reduced, or
// reprojected (the fuzzer found a GeoTIFF of 34 737 bands whose reduction copied every one).
TEST(DemImport, OnlyTheFirstBandIsRead) {
    const double utm[6] = {500000.0, 30.0, 0.0, 4000000.0, 0.0, -30.0};
    const double geographic[6] = {1.0, 0.0003, 0.0, 42.0, 0.0, -0.0003};
    // Band 1 rises 1 m a column from 100 m; the others are 9999 m everywhere.
    const auto value = [](int band, int col, int) { return band == 1 ? 100.0f + float(col) : 9999.0f; };
    const fs::path projected = writeTiff("terralux_bands_utm.tif", 32633, utm, 64, 48, 3, value);
    const fs::path lonLat = writeTiff("terralux_bands_geo.tif", 4326, geographic, 64, 48, 3, value);
    DemImportOptions reduced;
    reduced.maxResolution = 16;
    for (const auto& [path, options, what] : {std::tuple{projected, DemImportOptions{}, "as it is"},
                                              std::tuple{projected, reduced, "reduced"},
                                              std::tuple{lonLat, DemImportOptions{}, "reprojected"}}) {
        const auto r = importDem(path.string(), options);
        EXPECT_GE(r.heightfield.minHeight(), 99.9f) << what;
        EXPECT_LE(r.heightfield.maxHeight(), 163.1f) << what;
        EXPECT_GT(r.heightfield.maxHeight() - r.heightfield.minHeight(), 30.0f) << what;
    }
    fs::remove(projected);
    fs::remove(lonLat);
}

// One block of band 1 may decode to at most 1 GiB, counting every band a pixel-interleaved block
// carries; the fuzzer found a 367-byte GeoTIFF of 49 153 interleaved bands in 29 008 x 51 strips
// for which GDAL asked for 145 GB. The files here are sparse: no block is written or read.
TEST(DemImport, OversizedBlockIsRefusedBeforeAnyRead) {
    GDALAllRegister();
    GDALDriver* gtiff = GetGDALDriverManager()->GetDriverByName("GTiff");
    const auto sparse = [&](const std::string& name, int w, int h, int bands, GDALDataType type,
                            std::vector<std::string> options) {
        const fs::path path = fs::temp_directory_path() / name;
        options.insert(options.end(), {"SPARSE_OK=TRUE", "COMPRESS=DEFLATE"});
        CPLStringList list;
        for (const std::string& o : options) list.AddString(o.c_str());
        GDALDataset* ds = gtiff->Create(path.c_str(), w, h, bands, type, list.List());
        EXPECT_NE(ds, nullptr) << name;
        GDALClose(ds);
        return path;
    };
    // 20 000 x 64 cells x 500 bands x 2 bytes = 1 221 MiB a strip.
    const fs::path pixel =
        sparse("terralux_block_pixel.tif", 20000, 64, 500, GDT_Int16, {"INTERLEAVE=PIXEL", "BLOCKYSIZE=64"});
    EXPECT_EQ(importError(pixel.string()),
              pixel.string() + ": one block of band 1 decodes to 1221 MiB (20000 x 64 cells x 1000 bytes: 500 "
                               "bands interleaved by pixel); at most 1024 MiB; rewrite it tiled (gdal_translate "
                               "-co TILED=YES -co INTERLEAVE=BAND)");
    // The same bands each in their own strips: 2.4 MiB a block, and the import goes on.
    const fs::path band =
        sparse("terralux_block_band.tif", 20000, 64, 500, GDT_Int16, {"INTERLEAVE=BAND", "BLOCKYSIZE=64"});
    EXPECT_EQ(importError(band.string()), "");
    // One band in one strip of 17 000 x 16 000 Float32 cells: 1 038 MiB.
    const fs::path strip = sparse("terralux_block_strip.tif", 17000, 16000, 1, GDT_Float32, {"BLOCKYSIZE=16000"});
    EXPECT_EQ(importError(strip.string()),
              strip.string() + ": one block of band 1 decodes to 1038 MiB (17000 x 16000 cells x 4 bytes); at "
                               "most 1024 MiB; rewrite it tiled (gdal_translate -co TILED=YES)");
    // A tiled raster whose overview (a GDAL .ovr beside it) is one strip of 20 000 x 15 000 Float32
    // cells: a reduction may read the overview, so it counts too.
    const fs::path tiled = sparse("terralux_block_overview.tif", 40000, 30000, 1, GDT_Float32, {"TILED=YES"});
    const fs::path overview = fs::path(tiled.string() + ".ovr");
    CPLStringList overviewOptions;
    for (const char* o : {"SPARSE_OK=TRUE", "COMPRESS=DEFLATE", "BLOCKYSIZE=15000"}) overviewOptions.AddString(o);
    GDALClose(gtiff->Create(overview.c_str(), 20000, 15000, 1, GDT_Float32, overviewOptions.List()));
    EXPECT_EQ(importError(tiled.string()),
              tiled.string() + ": one block of band 1's overview 1 decodes to 1144 MiB (20000 x 15000 cells x 4 "
                               "bytes); at most 1024 MiB; rewrite it tiled (gdal_translate -co TILED=YES)");
    // A tiled raster whose mask (a GDAL .msk beside it, for the whole dataset) is in strips of
    // 40 000 x 28 000 bytes: resampling reads the mask beside the heights.
    const fs::path masked = sparse("terralux_block_mask.tif", 40000, 30000, 1, GDT_Float32, {"TILED=YES"});
    const fs::path mask = fs::path(masked.string() + ".msk");
    CPLStringList maskOptions;
    for (const char* o : {"SPARSE_OK=TRUE", "COMPRESS=DEFLATE", "BLOCKYSIZE=28000"}) maskOptions.AddString(o);
    GDALDataset* maskDs = gtiff->Create(mask.c_str(), 40000, 30000, 1, GDT_Byte, maskOptions.List());
    ASSERT_NE(maskDs, nullptr);
    maskDs->SetMetadataItem("INTERNAL_MASK_FLAGS_1", "2");  // GMF_PER_DATASET
    GDALClose(maskDs);
    EXPECT_EQ(importError(masked.string()),
              masked.string() + ": one block of the mask decodes to 1068 MiB (40000 x 28000 cells x 1 byte); at "
                                "most 1024 MiB; rewrite it tiled (gdal_translate -co TILED=YES)");
    // The fuzzer's file itself.
    const std::string found = std::string(TERRALUX_FUZZ_REGRESSIONS) + "/dem_tiff/interleaved_block_of_145_gb.tif";
    EXPECT_NE(importError(found).find("decodes to 138697 MiB (29008 x 51 cells x 98306 bytes: 49153 bands"),
              std::string::npos)
        << importError(found);
    for (const fs::path& p : {pixel, band, strip, tiled, overview, masked, mask}) fs::remove(p);
}

// A raster without a geotransform (a plain TIFF heightmap) is read as 1 m cells, north up, with a
// warning; GDAL's own default on failure is south-up, which the import must not take as rotated.
// Reduced, its cells widen with the reduction. Control points alone, or a CRS alone, place
// nothing and are refused.
TEST(DemImport, NoGeoTransformIsOneMetreCells) {
    GDALAllRegister();
    const fs::path path = fs::temp_directory_path() / "terralux_no_geotransform.tif";
    const auto write = [&](const std::function<void(GDALDataset&)>& georeference) {
        GDALDataset* ds =
            GetGDALDriverManager()->GetDriverByName("GTiff")->Create(path.c_str(), 40, 20, 1, GDT_Float32, nullptr);
        std::vector<float> v(800);
        for (int i = 0; i < 800; ++i) v[size_t(i)] = float(10 * (i / 40));  // rises 10 m a row
        EXPECT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, 40, 20, v.data(), 40, 20, GDT_Float32, 0, 0, nullptr),
                  CE_None);
        georeference(*ds);
        GDALClose(ds);
    };
    write([](GDALDataset&) {});
    const DemImportResult r = importDem(path.string());
    EXPECT_EQ(r.heightfield.width(), 40);
    EXPECT_EQ(r.heightfield.depth(), 20);
    EXPECT_DOUBLE_EQ(r.heightfield.cellSizeX(), 1.0);
    EXPECT_DOUBLE_EQ(r.heightfield.cellSizeZ(), 1.0);
    EXPECT_FLOAT_EQ(r.heightfield.at(0, 0), 0.0f);  // row 0 stays the first row
    EXPECT_FLOAT_EQ(r.heightfield.at(0, 19), 190.0f);
    EXPECT_NE(std::find(r.source.warnings.begin(), r.source.warnings.end(),
                        "no georeferencing: cells taken as 1 m, origin at 0"),
              r.source.warnings.end());
    DemImportOptions reduced;
    reduced.maxResolution = 10;
    const DemImportResult small = importDem(path.string(), reduced);
    EXPECT_EQ(small.heightfield.width(), 10);
    EXPECT_EQ(small.heightfield.depth(), 5);
    EXPECT_DOUBLE_EQ(small.heightfield.cellSizeX(), 4.0);
    EXPECT_DOUBLE_EQ(small.heightfield.cellSizeZ(), 4.0);

    write([](GDALDataset& ds) {
        OGRSpatialReference utm;
        utm.importFromEPSG(32631);
        GDAL_GCP gcps[3];
        GDALInitGCPs(3, gcps);
        const double at[3][4] = {{0, 0, 400000, 4700000}, {40, 0, 400040, 4700000}, {0, 20, 400000, 4699980}};
        for (int i = 0; i < 3; ++i) {
            gcps[i].dfGCPPixel = at[i][0];
            gcps[i].dfGCPLine = at[i][1];
            gcps[i].dfGCPX = at[i][2];
            gcps[i].dfGCPY = at[i][3];
        }
        ds.SetGCPs(3, gcps, &utm);
        GDALDeinitGCPs(3, gcps);
    });
    EXPECT_EQ(importError(path.string()),
              path.string() + ": is georeferenced by 3 control points, not a geotransform; warp it first (gdalwarp)");
    write([](GDALDataset& ds) {
        OGRSpatialReference utm;
        utm.importFromEPSG(32631);
        ds.SetSpatialRef(&utm);
    });
    EXPECT_EQ(importError(path.string()),
              path.string() + ": has a CRS but no geotransform: its cells cannot be placed in it");
    fs::remove(path);
}

// A footprint off the globe is refused before any reprojection (the fuzzer found one that kept
// GDAL's transformer busy for seconds), and one on it still imports.
TEST(DemImport, FootprintOffTheGlobeIsRefused) {
    const double farLongitude[6] = {1.0e15, 0.001, 0.0, 42.0, 0.0, -0.001};
    const fs::path geo = writeFlatTiff("terralux_off_globe_geo.tif", 4326, farLongitude);
    const std::string geoError = importError(geo.string());
    EXPECT_EQ(geoError, geo.string() + ": footprint corner (1000000000000000, 42) lies off the "
                                       "globe; longitude must be within +-540 and latitude "
                                       "within +-90.5 degrees");

    const double pastThePole[6] = {1.0, 0.001, 0.0, 91.0, 0.0, -0.001};
    const fs::path pole = writeFlatTiff("terralux_off_globe_pole.tif", 4326, pastThePole);
    EXPECT_NE(importError(pole.string()).find("lies off the globe"), std::string::npos);

    const double mercatorFar[6] = {3.0e7, 30.0, 0.0, 5.0e6, 0.0, -30.0};
    const fs::path merc = writeFlatTiff("terralux_off_globe_merc.tif", 3857, mercatorFar);
    EXPECT_NE(importError(merc.string()).find("Web Mercator coordinates must be within"),
              std::string::npos)
        << importError(merc.string());

    const double onTheGlobe[6] = {1.0, 0.001, 0.0, 42.0, 0.0, -0.001};
    const fs::path ok = writeFlatTiff("terralux_on_globe.tif", 4326, onTheGlobe);
    EXPECT_EQ(importError(ok.string()), "");
    for (const fs::path& p : {geo, pole, merc, ok}) fs::remove(p);
}

TEST(DemImport, MaxResolutionAreaAverages) {
    DemImportOptions o;
    o.maxResolution = 48;
    const auto r = importDem((kData / "bigtujunga_utm11_crop.tif").string(), o);
    EXPECT_TRUE(r.source.resampled);
    EXPECT_EQ(r.heightfield.width(), 48);
    EXPECT_EQ(r.heightfield.depth(), 32);
    EXPECT_DOUBLE_EQ(r.heightfield.cellSizeX(), 60.0);
    // Area averaging keeps the mean (to 0.02 %) and narrows the range.
    EXPECT_NEAR(meanHeight(r.heightfield), expected()["bigtujunga_utm11_crop.tif"]["mean"].get<double>(), 0.2);
    EXPECT_GT(r.heightfield.minHeight(), 569.0f);
    EXPECT_LT(r.heightfield.maxHeight(), 1589.0f);
}

// terrain.max_resolution keeps two cells across a thin raster (the fuzzer found a 24 x 23 320
// strip reduced to one column, a heightfield no surface can be made of).
TEST(DemImport, MaxResolutionKeepsTwoCellsAcrossAThinStrip) {
    const double gt[6] = {500000.0, 30.0, 0.0, 4000000.0, 0.0, -30.0};
    const fs::path tmp = writeFlatTiff("terralux_thin_strip.tif", 32633, gt, 4, 2000);
    DemImportOptions o;
    o.maxResolution = 256;
    const auto r = importDem(tmp.string(), o);
    fs::remove(tmp);
    EXPECT_EQ(r.heightfield.width(), 2);
    EXPECT_EQ(r.heightfield.depth(), 256);
    EXPECT_FLOAT_EQ(r.heightfield.at(1, 255), 100.0f);
}

// A reprojected, reduced import trims to the same footprint as the full-size one: the coverage
// raster that finds the footprint is built at twice the output's resolution, not the source's,
// and must still span the whole source.
TEST(DemImport, ReducedReprojectionKeepsTheFullFootprint) {
    // 1200 x 900 cells of about 80 m, 2.3 degrees east of UTM 31's central meridian: the grid
    // turns by 1.5 degrees, so the reprojected raster has wedges outside the source to trim.
    const double gt[6] = {4.7, 0.001, 0.0, 43.0, 0.0, -0.001};
    const fs::path tmp = writeFlatTiff("terralux_geo_reduced.tif", 4326, gt, 1200, 900);
    const auto full = importDem(tmp.string());
    DemImportOptions o;
    o.maxResolution = 128;
    const auto reduced = importDem(tmp.string(), o);
    fs::remove(tmp);
    ASSERT_TRUE(full.source.reprojected);
    ASSERT_TRUE(reduced.source.resampled);
    const Heightfield& f = full.heightfield;
    const Heightfield& r = reduced.heightfield;
    EXPECT_LE(std::max(r.width(), r.depth()), 128);
    // Nothing outside the source was kept (it would be nodata, filled).
    EXPECT_EQ(f.nodataCount(), 0u);
    EXPECT_EQ(r.nodataCount(), 0u);
    // The same footprint, to within the trim of one reduced cell a side.
    const double spanX = double(r.width()) * r.cellSizeX(), spanZ = double(r.depth()) * r.cellSizeZ();
    EXPECT_NEAR(spanX, double(f.width()) * f.cellSizeX(), 2.0 * r.cellSizeX());
    EXPECT_NEAR(spanZ, double(f.depth()) * f.cellSizeZ(), 2.0 * r.cellSizeZ());
    EXPECT_NEAR(r.geo.easting, f.geo.easting, r.cellSizeX());
    EXPECT_NEAR(r.geo.northing, f.geo.northing, r.cellSizeZ());
}

TEST(DemImport, VerticalScaleMultipliesHeights) {
    DemImportOptions o;
    o.verticalScale = 2.0;
    const auto r = importDem((kData / "bigtujunga_utm11_crop.tif").string(), o);
    EXPECT_FLOAT_EQ(r.heightfield.maxHeight(), 2.0f * 1589.0f);
}

TEST(DemImport, EmbeddedSample) {
    const auto r = importDemFromMemory(kSampleTerrainName, sampleTerrainBytes(), sampleTerrainSize());
    EXPECT_EQ(r.heightfield.width(), 256);
    EXPECT_EQ(r.heightfield.depth(), 256);
    EXPECT_DOUBLE_EQ(r.heightfield.cellSizeX(), 30.0);
    EXPECT_FLOAT_EQ(r.heightfield.minHeight(), 529.0f);
    EXPECT_FLOAT_EQ(r.heightfield.maxHeight(), 1953.0f);
    EXPECT_EQ(r.source.path, kSampleTerrainName);
}

TEST(DemImport, BadInputNamesTheFileAndTheProblem) {
    const std::string missing = (kData / "does_not_exist.tif").string();
    EXPECT_EQ(importError(missing), missing + ": no such file");

    const std::string text = (kData / "not_a_raster.tif").string();
    EXPECT_EQ(importError(text).rfind(text + ": not a raster GDAL can read", 0), 0u) << importError(text);

    const std::string allNodata = (kData / "all_nodata.asc").string();
    EXPECT_EQ(importError(allNodata), allNodata + ": every cell is nodata; nothing to import");

    const std::string nan = (kData / "nan_values.asc").string();
    EXPECT_NE(importError(nan).find(nan + ": non-finite height at column 1, row 1"), std::string::npos)
        << importError(nan);

    const fs::path empty = fs::temp_directory_path() / "terralux_empty.tif";
    std::ofstream(empty).close();
    EXPECT_EQ(importError(empty.string()), empty.string() + ": file is empty");
    fs::remove(empty);

    EXPECT_EQ(importError(kData.string()), kData.string() + ": is a directory, not a raster");

    DemImportOptions tiny;
    tiny.maxCells = 1000;
    const std::string big = (kData / "bigtujunga_utm11_crop.tif").string();
    EXPECT_NE(importError(big, tiny).find("too large to hold in memory; set terrain.max_resolution"),
              std::string::npos);

    // A grid that declares far more cells than it holds is refused before GDAL's averaging asks
    // for gigabytes: 240000 x 9940000 cells in a few bytes, reduced to 256 on its long side.
    const fs::path huge = fs::temp_directory_path() / "terralux_declares_huge.asc";
    std::ofstream(huge) << "ncols 240000\nnrows 9940000\nxllcorner 0\nyllcorner 0\ncellsize 9\n1 2 3\n";
    DemImportOptions reduced;
    reduced.maxResolution = 256;
    const std::string hugeError = importError(huge.string(), reduced);
    EXPECT_EQ(hugeError, huge.string() +
                             ": raster 240000x9940000 is too large to average down to 6x256 "
                             "(1553125000 source cells per output cell, at most 67108864); raise "
                             "terrain.max_resolution or crop the DEM");
    fs::remove(huge);

    // Messages are one line.
    for (const auto& m : {importError(text), importError(nan), importError(allNodata), hugeError})
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
}

TEST(DemImport, UtmZones) {
    EXPECT_EQ(utmEpsgFor(1.5, 42.5), 32631);
    EXPECT_EQ(utmEpsgFor(-121.5, 46.5), 32610);
    EXPECT_EQ(utmEpsgFor(-179.9, -10.0), 32701);
    EXPECT_EQ(utmEpsgFor(179.9, 10.0), 32660);
    EXPECT_EQ(utmEpsgFor(180.0, 10.0), 32601);
}

// The full real DEMs, when the shared data folder is present.
TEST(DemImportShared, RealDems) {
    if (!fs::exists(kShared / "N42E001.hgt")) GTEST_SKIP() << "shared DEMs not present at " << kShared;
    {
        const auto r = importDem((kShared / "N42E001.hgt").string());
        EXPECT_EQ(r.source.driver, "SRTMHGT");
        EXPECT_EQ(r.heightfield.geo.epsg, 32631);
        // 7,652 void pixels (0.53 %) in the source stay flagged after the warp.
        const double share = double(r.heightfield.nodataCount()) / double(r.heightfield.heights().size());
        EXPECT_GT(share, 0.003);
        EXPECT_LT(share, 0.01);
        EXPECT_GE(r.heightfield.minHeight(), 349.0f - 1.0f);
        EXPECT_LE(r.heightfield.maxHeight(), 3100.0f + 1.0f);
    }
    {
        const auto r = importDem((kShared / "srtm_bigtujunga30m_utm11.tif").string());
        EXPECT_EQ(r.heightfield.width(), 1197);
        EXPECT_EQ(r.heightfield.depth(), 643);
        EXPECT_EQ(r.heightfield.nodataCount(), 0u);
        EXPECT_FLOAT_EQ(r.heightfield.minHeight(), 315.0f);
        EXPECT_FLOAT_EQ(r.heightfield.maxHeight(), 2295.0f);
    }
    {
        DemImportOptions o;
        o.maxResolution = 300;
        const auto r = importDem((kShared / "mt_rainier_90m.tif").string(), o);
        EXPECT_TRUE(r.source.resampled);
        EXPECT_LE(std::max(r.heightfield.width(), r.heightfield.depth()), 300);
        EXPECT_EQ(r.heightfield.geo.epsg, 32610);
    }
    {
        const std::string zip = "/vsizip/" + (kShared / "..").string();  // not a zip: clean error
        EXPECT_THROW(importDem(zip + "/nothing.zip/x.tif"), DemError);
    }
}

// The coverage of a reprojected grid is held as runs a row: a row of a rotated footprint is one
// run, a concave footprint's two, an uncovered row none; covers() answers as the cells did.
TEST(CoverageRuns, HoldARowsCoveredColumnsAsRuns) {
    CoverageRuns c;
    c.width = 8;
    c.rows.resize(3);
    const uint8_t one[8] = {0, 0, 1, 1, 1, 1, 1, 0};
    const uint8_t two[8] = {1, 1, 0, 0, 1, 0, 1, 1};
    const uint8_t none[8] = {};
    c.addRow(0, one);
    c.addRow(1, two);
    c.addRow(2, none);
    EXPECT_EQ(c.rows[0], (std::vector<std::pair<int, int>>{{2, 6}}));
    EXPECT_EQ(c.rows[1], (std::vector<std::pair<int, int>>{{0, 1}, {4, 4}, {6, 7}}));
    EXPECT_TRUE(c.rows[2].empty());
    const uint8_t* rows[3] = {one, two, none};
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 8; ++x) EXPECT_EQ(c.covers(x, y), rows[y][x] != 0) << x << ", " << y;
}
