#include "DemImport.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <mutex>
#include <atomic>
#include <sstream>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>
#include <gdal_alg.h>
#include <gdal_priv.h>
#include <gdal_utils.h>
#include <gdalwarper.h>
#include <ogr_spatialref.h>

#include "GdalSupport.h"
#include "Membrane.h"

namespace terralux {
namespace {

// Sentinel written by our own warps where the output has no source data; a float that no DEM
// holds, so it cannot collide with a real height.
constexpr double kWarpNodata = -3.0e38;

using gdal::DatasetPtr;
using gdal::fmt;
using gdal::registerDriversOnce;
using QuietGdalErrors = gdal::QuietErrors;

[[noreturn]] void fail(const std::string& path, const std::string& what) {
    throw DemError(path + ": " + what);
}

std::string withGdalReason(const std::string& what) { return gdal::withReason(what); }

// A one-band MEM dataset over `data` (w × h samples of `type`, row-major), which must outlive it;
// null when GDAL refuses it.
DatasetPtr memOver(void* data, int w, int h, GDALDataType type) {
    GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
    DatasetPtr ds(mem ? mem->Create("", w, h, 0, type, nullptr) : nullptr);
    if (!ds) return ds;
    char pointer[64] = {};
    CPLPrintPointer(pointer, data, sizeof pointer - 1);
    const std::string option = std::string("DATAPOINTER=") + pointer;
    char* options[] = {const_cast<char*>(option.c_str()), nullptr};
    if (static_cast<GDALDataset*>(ds.get())->AddBand(type, options) != CE_None) return {};
    return ds;
}

DatasetPtr warpTo(const std::string& path, GDALDatasetH src, const std::vector<std::string>& args) {
    std::string why;
    DatasetPtr out = gdal::warp(src, args, why);
    if (!out) fail(path, why);
    return out;
}

DatasetPtr translateTo(const std::string& path, GDALDatasetH src,
                       const std::vector<std::string>& args) {
    std::string why;
    DatasetPtr out = gdal::translate(src, args, why);
    if (!out) fail(path, why);
    return out;
}

std::string srsName(const OGRSpatialReference& srs) {
    const char* name = srs.GetName();
    return name ? name : "";
}

int srsEpsg(const OGRSpatialReference& srs) {
    OGRSpatialReference copy(srs);
    const char* code = copy.GetAuthorityCode(nullptr);
    const char* authority = copy.GetAuthorityName(nullptr);
    if (!code || !authority || std::string(authority) != "EPSG") {
        if (copy.AutoIdentifyEPSG() != OGRERR_NONE) return 0;
        code = copy.GetAuthorityCode(nullptr);
    }
    return code ? std::atoi(code) : 0;
}

bool isWebMercator(const OGRSpatialReference& srs) {
    const int epsg = srsEpsg(srs);
    if (epsg == 3857 || epsg == 900913 || epsg == 3785) return true;
    return srsName(srs).find("Pseudo-Mercator") != std::string::npos;
}

// Target size for a warp, as gdalwarp would choose it, so that maxResolution can be applied in
// the same pass (area averaging) instead of warping at full size first.
bool suggestedWarpSize(GDALDatasetH src, const std::string& dstWkt, int& w, int& h) {
    void* transformer = GDALCreateGenImgProjTransformer(src, nullptr, nullptr, dstWkt.c_str(),
                                                        FALSE, 0.0, 0);
    if (!transformer) return false;
    double gt[6];
    const CPLErr err =
        GDALSuggestedWarpOutput(src, GDALGenImgProjTransform, transformer, gt, &w, &h);
    GDALDestroyGenImgProjTransformer(transformer);
    return err == CE_None && w > 0 && h > 0;
}

// Largest axis-aligned window whose border rows and columns are all covered. The coverage of a
// reprojected raster is a slightly rotated rectangle; trimming its ragged edges keeps only
// measured terrain rather than extrapolating into the wedges outside the source.
struct Window {
    int x0, y0, x1, y1;  // inclusive
};
Window coveredWindow(const CoverageRuns& cov) {
    const int w = cov.width, h = int(cov.rows.size());
    Window win{0, 0, w - 1, h - 1};
    auto rowGaps = [&](int y) {
        int covered = 0;
        for (const auto& [a, b] : cov.rows[size_t(y)])
            covered += std::max(0, std::min(b, win.x1) - std::max(a, win.x0) + 1);
        return (win.x1 - win.x0 + 1) - covered;
    };
    auto colGaps = [&](int x) {
        int n = 0;
        for (int y = win.y0; y <= win.y1; ++y) n += !cov.covers(x, y);
        return n;
    };
    while (win.x0 <= win.x1 && win.y0 <= win.y1) {
        const int gaps[4] = {rowGaps(win.y0), rowGaps(win.y1), colGaps(win.x0), colGaps(win.x1)};
        const int worst = int(std::max_element(gaps, gaps + 4) - gaps);
        if (gaps[worst] == 0) break;
        switch (worst) {
            case 0: ++win.y0; break;
            case 1: --win.y1; break;
            case 2: ++win.x0; break;
            default: --win.x1; break;
        }
    }
    return win;
}

}  // namespace

MembraneReport fillVoids(std::vector<float>& heights, int w, int h, const std::vector<uint8_t>& nodata,
                         VoidFill method) {
    if (w < 1 || h < 1 || heights.size() != size_t(w) * size_t(h) || nodata.size() != heights.size())
        throw DemError("filling nodata cells: grid " + std::to_string(w) + " x " + std::to_string(h) + " has " +
                       std::to_string(heights.size()) + " heights and " + std::to_string(nodata.size()) +
                       " mask cells; both must be w x h");
    const size_t holes = size_t(std::count_if(nodata.begin(), nodata.end(), [](uint8_t v) { return v != 0; }));
    if (holes == 0) return {};
    if (holes == nodata.size()) throw DemError("filling nodata cells: every cell is nodata; nothing to fill from");
    if (method == VoidFill::Membrane) {
        try {
            return membraneFill(heights, w, h, nodata, MembraneStart::RimMean);
        } catch (const std::bad_alloc&) {
            throw DemError("filling nodata cells: not enough memory for the membrane over " + std::to_string(holes) +
                           " cells; set terrain.max_resolution");
        }
    }
    registerDriversOnce();
    QuietGdalErrors quiet;
    // GDALFillNodata interpolates by inverse distance weighting over a search in four directions,
    // then runs 3x3 smoothing passes over the filled cells only. The search reaches the whole
    // grid, so every hole is filled.
    // The MEM datasets read and write our own buffers: no copy of the grid for GDAL.
    std::vector<uint8_t> valid(nodata.size());
    for (size_t i = 0; i < nodata.size(); ++i) valid[i] = nodata[i] ? 0 : 1;
    DatasetPtr fillDs = memOver(heights.data(), w, h, GDT_Float32);
    DatasetPtr maskDs = memOver(valid.data(), w, h, GDT_Byte);
    if (!fillDs || !maskDs) throw DemError(withGdalReason("filling nodata cells failed"));
    auto* fb = static_cast<GDALDataset*>(fillDs.get())->GetRasterBand(1);
    auto* mb = static_cast<GDALDataset*>(maskDs.get())->GetRasterBand(1);
    if (GDALFillNodata(fb, mb, double(std::max(w, h)) * 1.5, 0, 2, nullptr, nullptr, nullptr) != CE_None)
        throw DemError(withGdalReason("filling nodata cells failed"));
    static_cast<GDALDataset*>(fillDs.get())->FlushCache();
    return {};
}

namespace {

// The footprint centre in WGS 84 longitude and latitude, and the true azimuth of grid north
// there: the initial bearing from the centre to a point 1 km up the grid (the sun's azimuth
// from a date and a time is true, the engine's is grid). Left unlocated when PROJ cannot
// transform: the DEM still imports, only the date-and-time sun needs the place.
void locateOnEarth(GeoOrigin& geo, double unit) {
    OGRSpatialReference crs, wgs84;
    if (crs.importFromWkt(geo.crsWkt.c_str()) != OGRERR_NONE) return;
    crs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    wgs84.SetWellKnownGeogCS("WGS84");
    wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    std::unique_ptr<OGRCoordinateTransformation> toGeo(OGRCreateCoordinateTransformation(&crs, &wgs84));
    if (!toGeo) return;
    double x[2] = {geo.easting / unit, geo.easting / unit};
    double y[2] = {geo.northing / unit, (geo.northing + 1000.0) / unit};
    if (!toGeo->Transform(2, x, y) || !std::isfinite(x[0] + y[0] + x[1] + y[1])) return;
    constexpr double d = 3.14159265358979323846 / 180.0;
    const double p1 = y[0] * d, p2 = y[1] * d, dl = (x[1] - x[0]) * d;
    geo.longitudeDeg = x[0];
    geo.latitudeDeg = y[0];
    geo.gridConvergenceDeg =
        std::atan2(std::sin(dl) * std::cos(p2), std::cos(p1) * std::sin(p2) - std::sin(p1) * std::cos(p2) * std::cos(dl)) / d;
}

}  // namespace

void CoverageRuns::addRow(int y, const uint8_t* cells) {
    std::vector<std::pair<int, int>>& runs = rows.at(size_t(y));
    runs.clear();
    for (int x = 0; x < width;) {
        if (!cells[x]) {
            ++x;
            continue;
        }
        const int first = x;
        while (x < width && cells[x]) ++x;
        runs.emplace_back(first, x - 1);
    }
}

bool CoverageRuns::covers(int x, int y) const {
    for (const auto& [a, b] : rows[size_t(y)])
        if (x >= a && x <= b) return true;
    return false;
}

int utmEpsgFor(double longitudeDeg, double latitudeDeg) {
    double lon = std::fmod(longitudeDeg + 180.0, 360.0);
    if (lon < 0) lon += 360.0;
    const int zone = std::clamp(int(std::floor(lon / 6.0)) + 1, 1, 60);
    return (latitudeDeg >= 0.0 ? 32600 : 32700) + zone;
}

namespace {

// importDem, and demGrid (`gridOnly` set): that returns as soon as the grid is known, before any
// height is read but the streamed minimum and maximum.
DemImportResult importDemImpl(const std::string& path, const DemImportOptions& options, DemGrid* gridOnly) {
    registerDriversOnce();
    QuietGdalErrors quiet;

    const bool isVirtual = path.rfind("/vsi", 0) == 0;
    if (path.empty()) throw DemError("DEM path is empty");
    if (!isVirtual) {
        std::error_code ec;
        if (!std::filesystem::exists(path, ec)) fail(path, "no such file");
        if (std::filesystem::is_directory(path, ec)) fail(path, "is a directory, not a raster");
        if (std::filesystem::file_size(path, ec) == 0 && !ec) fail(path, "file is empty");
    }
    if (options.maxResolution < 0) fail(path, "maximum resolution must be >= 0");

    DatasetPtr src(GDALOpenEx(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY, nullptr, nullptr,
                              nullptr));
    if (!src) fail(path, withGdalReason("not a raster GDAL can read"));
    auto* ds = static_cast<GDALDataset*>(src.get());

    DemImportResult result;
    DemSourceInfo& info = result.source;
    info.path = path;
    info.driver = ds->GetDriver() ? ds->GetDriver()->GetDescription() : "";
    info.sourceWidth = ds->GetRasterXSize();
    info.sourceHeight = ds->GetRasterYSize();
    if (ds->GetRasterCount() < 1) fail(path, "has no raster band");
    if (const std::string block = gdal::oversizedBlock(src.get()); !block.empty()) fail(path, block);
    // The heights are the first band. The others (a mask, colours, or thousands in a crafted file)
    // would each get their own copy in a reprojection or a reduction, so those read a one-band view.
    DatasetPtr firstBand;
    if (ds->GetRasterCount() > 1) firstBand = translateTo(path, src.get(), {"-of", "VRT", "-b", "1"});
    GDALDatasetH heightSource = firstBand ? firstBand.get() : src.get();
    // A surface needs two samples each way: fewer make a footprint of no width and no mesh.
    if (info.sourceWidth < 2 || info.sourceHeight < 2)
        fail(path, "raster is " + std::to_string(info.sourceWidth) + " x " +
                       std::to_string(info.sourceHeight) + " cells; a DEM needs at least 2 x 2");

    double gt[6] = {0, 1, 0, 0, 0, -1};
    const bool hasGeoTransform = ds->GetGeoTransform(gt) == CE_None;
    if (!hasGeoTransform) {
        // Control points alone place the raster only through a warp we do not make, and a CRS
        // without a geotransform places nothing.
        if (ds->GetGCPCount() > 0)
            fail(path, "is georeferenced by " + std::to_string(ds->GetGCPCount()) +
                           " control points, not a geotransform; warp it first (gdalwarp)");
        const OGRSpatialReference* crs = ds->GetSpatialRef();
        if (crs && !crs->IsEmpty())
            fail(path, "has a CRS but no geotransform: its cells cannot be placed in it");
        // GDAL fills in its own default on failure, south-up (a positive row step); rows go south.
        const double northUp[6] = {0, 1, 0, 0, 0, -1};
        std::copy(std::begin(northUp), std::end(northUp), gt);
        info.warnings.push_back("no georeferencing: cells taken as 1 m, origin at 0");
    }
    info.sourcePixelX = gt[1];
    info.sourcePixelY = gt[5];

    const OGRSpatialReference* srcSrs = ds->GetSpatialRef();
    const bool hasCrs = srcSrs && !srcSrs->IsEmpty();
    if (hasCrs) {
        info.sourceCrs = srsName(*srcSrs);
        info.sourceEpsg = srsEpsg(*srcSrs);
        if (srcSrs->IsGeographic()) {
            info.sourcePixelUnit = "deg";
        } else {
            const char* unit = nullptr;
            const double toMetres = srcSrs->GetLinearUnits(&unit);
            info.sourcePixelUnit = toMetres == 1.0 ? "m" : unit && *unit ? unit : "unknown unit";
            if (info.sourcePixelUnit == "foot") info.sourcePixelUnit = "ft";
        }
    } else if (hasGeoTransform) {
        info.warnings.push_back("no CRS: coordinates and cell sizes taken as metres");
    }

    const bool rotated = gt[2] != 0.0 || gt[4] != 0.0 || gt[5] > 0.0;
    const bool needsMetric = hasCrs && (srcSrs->IsGeographic() || isWebMercator(*srcSrs));
    info.geographic = needsMetric;
    if (rotated && !hasCrs)
        fail(path, "rotated or south-up geotransform without a CRS cannot be resampled");
    if (!(std::isfinite(gt[1]) && std::isfinite(gt[5])) || gt[1] == 0.0 || gt[5] == 0.0)
        fail(path, "pixel size " + fmt(gt[1]) + " x " + fmt(gt[5]) + " must be finite and non-zero");
    // A footprint off the globe is a broken file, and handing it to GDAL's transformers can
    // take seconds per point (a fuzzed GeoTIFF hit 5 s in one Transform), so refuse it first.
    if (needsMetric) {
        const bool geographic = srcSrs->IsGeographic();
        // Degrees per CRS unit for geographic CRSs (radians or gradians are legal); Web
        // Mercator's square world is 2 x 20 037 508.34 m wide, allowed 1 % over.
        double degPerUnit = geographic ? srcSrs->GetAngularUnits() * 180.0 / M_PI : 1.0;
        if (std::abs(degPerUnit - 1.0) < 1e-9) degPerUnit = 1.0;  // degrees, so messages stay exact
        const double limX = geographic ? 540.0 : 20037508.3428 * 1.01;
        const double limY = geographic ? 90.5 : 20037508.3428 * 1.01;
        for (const double i : {0.0, double(info.sourceWidth)}) {
            for (const double j : {0.0, double(info.sourceHeight)}) {
                const double x = (gt[0] + gt[1] * i + gt[2] * j) * degPerUnit;
                const double y = (gt[3] + gt[4] * i + gt[5] * j) * degPerUnit;
                if (!(std::abs(x) <= limX && std::abs(y) <= limY))
                    fail(path, "footprint corner (" + fmt(x) + ", " + fmt(y) + ") lies off the globe" +
                                   (geographic ? "; longitude must be within +-540 and latitude "
                                                 "within +-90.5 degrees"
                                               : "; Web Mercator coordinates must be within "
                                                 "+-20 237 883 m"));
            }
        }
    }

    GDALRasterBand* band = ds->GetRasterBand(1);
    int hasNodata = 0;
    const double srcNodata = band->GetNoDataValue(&hasNodata);

    // Pick the output grid: metric CRS, north up, optionally reduced.
    DatasetPtr work;        // the grid we finally read (may be src itself)
    bool lazyWarp = false;  // work is a virtual warp or resampling of the source, read on demand
    CoverageRuns coverage;  // where the warped output lies inside the source footprint
    GDALDatasetH readFrom = heightSource;
    const double maxCells = options.maxCells;

    // GDAL averages one output cell from one buffer of the source cells it covers, so a raster
    // that declares far more cells than it can hold (a 90-byte ASCII grid that claims
    // 240000 x 9940000) would ask for gigabytes before the first row is read. Refuse a
    // reduction whose buffer per output cell passes 256 MiB of 4-byte samples.
    auto checkReduction = [&](int outW, int outH) {
        const double perCell =
            (double(info.sourceWidth) / outW) * (double(info.sourceHeight) / outH);
        constexpr double kMaxCellsPerOutput = 256.0 * 1024 * 1024 / 4;
        if (perCell > kMaxCellsPerOutput)
            fail(path, "raster " + std::to_string(info.sourceWidth) + "x" +
                           std::to_string(info.sourceHeight) + " is too large to average down to " +
                           std::to_string(outW) + "x" + std::to_string(outH) + " (" +
                           fmt(std::round(perCell)) + " source cells per output cell, at most " +
                           fmt(kMaxCellsPerOutput) +
                           "); raise terrain.max_resolution or crop the DEM");
    };

    auto reducedSize = [&](int w, int h, int& rw, int& rh) {
        rw = w;
        rh = h;
        if (options.maxResolution > 0 && std::max(w, h) > options.maxResolution) {
            const double s = double(options.maxResolution) / std::max(w, h);
            // Two cells each way at least (a surface needs them), however thin the raster.
            rw = std::min(w, std::max(2, int(std::lround(w * s))));
            rh = std::min(h, std::max(2, int(std::lround(h * s))));
        }
    };

    if (needsMetric || rotated) {
        OGRSpatialReference dst;
        if (needsMetric) {
            // Centre of the footprint in longitude/latitude picks the UTM zone.
            OGRSpatialReference wgs84;
            wgs84.SetWellKnownGeogCS("WGS84");
            wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
            OGRSpatialReference srcCopy(*srcSrs);
            srcCopy.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
            std::unique_ptr<OGRCoordinateTransformation> toGeo(
                OGRCreateCoordinateTransformation(&srcCopy, &wgs84));
            double cx = gt[0] + gt[1] * info.sourceWidth * 0.5 + gt[2] * info.sourceHeight * 0.5;
            double cy = gt[3] + gt[4] * info.sourceWidth * 0.5 + gt[5] * info.sourceHeight * 0.5;
            if (!toGeo || !toGeo->Transform(1, &cx, &cy))
                fail(path, withGdalReason("cannot locate the footprint centre in WGS 84"));
            dst.importFromEPSG(utmEpsgFor(cx, cy));
        } else {
            dst = *srcSrs;
        }
        char* wktRaw = nullptr;
        dst.exportToWkt(&wktRaw);
        const std::string dstWkt = wktRaw ? wktRaw : "";
        CPLFree(wktRaw);

        int fullW = 0, fullH = 0;
        if (!suggestedWarpSize(heightSource, dstWkt, fullW, fullH))
            fail(path, withGdalReason("cannot compute the reprojected grid"));
        int outW, outH;
        reducedSize(fullW, fullH, outW, outH);
        // A window's heights are checked once its size is known (the coverage holds its runs, a
        // few integers a row).
        if (!(options.window || gridOnly) && double(outW) * outH > maxCells)
            fail(path, "reprojected raster " + std::to_string(outW) + "x" + std::to_string(outH) +
                           " is too large to hold in memory; set terrain.max_resolution");
        checkReduction(outW, outH);

        // -wm: GDAL's warp buffers (64 MB by default) at 8 MB, so a bake's peak memory stays a
        // few rasters (bench_bake_memory); chunking costs no accuracy.
        // Only the grid, or a window of it: a virtual warp, which warps the blocks read and no
        // others (so a tile of a geographic DEM never warps the whole raster). Its blocks are the
        // whole grid's, so every window sees the same value in a cell.
        lazyWarp = gridOnly || options.window.has_value();
        if (options.window && !gridOnly) info.windowRead = true;
        std::vector<std::string> args = {"-of", lazyWarp ? "VRT" : "MEM", "-t_srs", dstWkt, "-ot", "Float32",
                                         "-dstnodata", fmt(kWarpNodata), "-wm", "8"};
        if (outW != fullW || outH != fullH) {
            args.insert(args.end(), {"-ts", std::to_string(outW), std::to_string(outH), "-r",
                                     "average"});
            info.resampled = true;
        } else {
            args.insert(args.end(), {"-r", "bilinear"});
        }
        if (hasNodata) args.insert(args.end(), {"-srcnodata", fmt(srcNodata)});
        work = warpTo(path, heightSource, args);
        info.reprojected = needsMetric;

        // Same warp of an all-ones raster: where the output has no source at all. Coverage
        // depends only on the footprint, so the ones raster spans it at no more than twice the
        // output's resolution instead of the source's (fewer source cells for the warp to visit).
        // It holds no cells: a virtual band with no sources reads as its nodata value, 1, which
        // the warp is told not to treat as nodata.
        const int onesW = std::min(info.sourceWidth, 2 * outW + 2);
        const int onesH = std::min(info.sourceHeight, 2 * outH + 2);
        const double sx = double(info.sourceWidth) / onesW, sy = double(info.sourceHeight) / onesH;
        double onesGt[6] = {gt[0], gt[1] * sx, gt[2] * sy, gt[3], gt[4] * sx, gt[5] * sy};
        GDALDriver* vrt = GetGDALDriverManager()->GetDriverByName("VRT");
        DatasetPtr ones(vrt ? vrt->Create("", onesW, onesH, 1, GDT_Byte, nullptr) : nullptr);
        if (!ones) fail(path, withGdalReason("cannot create the coverage raster"));
        auto* onesDs = static_cast<GDALDataset*>(ones.get());
        onesDs->SetGeoTransform(onesGt);
        onesDs->SetSpatialRef(srcSrs);
        onesDs->GetRasterBand(1)->SetNoDataValue(1.0);
        // On the heights' own grid: the same extent and size, so coverage cell (i, j) is
        // heights cell (i, j) by construction, not because both warps chose alike.
        double wgt[6];
        static_cast<GDALDataset*>(work.get())->GetGeoTransform(wgt);
        const int ww = static_cast<GDALDataset*>(work.get())->GetRasterXSize();
        const int wh = static_cast<GDALDataset*>(work.get())->GetRasterYSize();
        // A virtual warp, read a strip of rows at a time into runs: never a byte a cell of the grid.
        DatasetPtr warped = warpTo(path, ones.get(),
                                   {"-of", "VRT", "-t_srs", dstWkt, "-te", fmt(wgt[0]), fmt(wgt[3] + wgt[5] * wh),
                                    fmt(wgt[0] + wgt[1] * ww), fmt(wgt[3]), "-ts", std::to_string(ww),
                                    std::to_string(wh), "-r", "near", "-srcnodata", "None", "-dstnodata", "0",
                                    "-wm", "8"});
        auto* c = static_cast<GDALDataset*>(warped.get());
        if (c->GetRasterXSize() != ww || c->GetRasterYSize() != wh)
            fail(path, "reprojected coverage of " + std::to_string(c->GetRasterXSize()) + "x" +
                           std::to_string(c->GetRasterYSize()) + " cells does not match the " + std::to_string(ww) +
                           "x" + std::to_string(wh) + " grid");
        coverage.width = ww;
        coverage.rows.resize(size_t(wh));
        constexpr int kStrip = 256;
        std::vector<uint8_t> strip;
        for (int y0 = 0; y0 < wh; y0 += kStrip) {
            const int rows = std::min(kStrip, wh - y0);
            strip.resize(size_t(ww) * size_t(rows));
            if (c->GetRasterBand(1)->RasterIO(GF_Read, 0, y0, ww, rows, strip.data(), ww, rows, GDT_Byte, 0, 0,
                                              nullptr) != CE_None)
                fail(path, withGdalReason("cannot read the reprojected coverage"));
            for (int r = 0; r < rows; ++r) coverage.addRow(y0 + r, strip.data() + size_t(r) * size_t(ww));
        }
        readFrom = work.get();
    } else {
        int outW, outH;
        reducedSize(info.sourceWidth, info.sourceHeight, outW, outH);
        if (outW == info.sourceWidth && outH == info.sourceHeight && gridOnly) {
            // The source's cells are the grid's: the header and one streamed pass say it all.
            double minMax[2] = {0.0, 0.0};
            if (GDALComputeRasterMinMax(GDALGetRasterBand(heightSource, 1), FALSE, minMax) != CE_None)
                fail(path, withGdalReason("cannot read band 1"));
            double u = 1.0;
            if (hasCrs) u = srcSrs->GetLinearUnits() > 0.0 ? srcSrs->GetLinearUnits() : 1.0;
            *gridOnly = {outW, outH, std::abs(gt[1]) * u, std::abs(gt[5]) * u,
                         minMax[0] * options.verticalScale, minMax[1] * options.verticalScale, true};
            return result;
        }
        const bool direct = outW == info.sourceWidth && outH == info.sourceHeight;
        // Reduced, for the grid or a window of it: a virtual resampling, as the warp above.
        lazyWarp = !direct && (gridOnly || options.window.has_value());
        if (options.window && !gridOnly) info.windowRead = true;  // checked against the grid below
        if (double(outW) * outH > maxCells && !info.windowRead && !gridOnly)
            fail(path, "raster " + std::to_string(outW) + "x" + std::to_string(outH) +
                           " is too large to hold in memory; set terrain.max_resolution");
        checkReduction(outW, outH);
        if (outW != info.sourceWidth || outH != info.sourceHeight) {
            work = translateTo(path, heightSource,
                               {"-of", lazyWarp ? "VRT" : "MEM", "-ot", "Float32", "-outsize", std::to_string(outW),
                                std::to_string(outH), "-r", "average"});
            readFrom = work.get();
            info.resampled = true;
        }
    }
    // Each GDAL dataset goes as soon as it has been read, so the import holds at most one grid
    // of GDAL's beside its own: the source (and its cached blocks) once a working copy exists,
    // the coverage once read.
    if (work && !lazyWarp) {
        firstBand.reset();  // the view reads the source: it goes first
        src.reset();
    }

    auto* rd = static_cast<GDALDataset*>(readFrom);
    // The grid: a reprojected raster trimmed to the window that lies wholly inside the source
    // footprint, whose first cell is (x0, y0) of the warp.
    int x0 = 0, y0 = 0;
    int gridW = rd->GetRasterXSize(), gridH = rd->GetRasterYSize();
    if (!coverage.rows.empty()) {
        if (coverage.width != gridW || coverage.rows.size() != size_t(gridH))
            fail(path, "reprojected coverage of " + std::to_string(coverage.width) + "x" +
                           std::to_string(coverage.rows.size()) + " cells does not match the " + std::to_string(gridW) +
                           "x" + std::to_string(gridH) + " grid");
        const Window win = coveredWindow(coverage);
        coverage = {};
        if (win.x0 > win.x1 || win.y0 > win.y1) fail(path, "reprojected raster has no coverage");
        x0 = win.x0;
        y0 = win.y0;
        gridW = win.x1 - win.x0 + 1;
        gridH = win.y1 - win.y0 + 1;
    }
    // A sliver footprint can reproject to a single row or column.
    if (gridW < 2 || gridH < 2)
        fail(path, "imports as " + std::to_string(gridW) + " x " + std::to_string(gridH) +
                       " cells; a DEM needs at least 2 x 2");
    int w = gridW, h = gridH;
    int readX = x0, readY = y0;
    if (info.windowRead) {
        const GridWindow& win = *options.window;
        if (win.cols < 2 || win.rows < 2 || win.col0 < 0 || win.row0 < 0 || win.col0 + win.cols > gridW ||
            win.row0 + win.rows > gridH)
            fail(path, "window " + std::to_string(win.cols) + "x" + std::to_string(win.rows) + " at (" +
                           std::to_string(win.col0) + ", " + std::to_string(win.row0) + ") must lie inside the " +
                           std::to_string(gridW) + "x" + std::to_string(gridH) + " grid, 2 x 2 at least");
        if (double(win.cols) * win.rows > maxCells)
            fail(path, "window " + std::to_string(win.cols) + "x" + std::to_string(win.rows) +
                           " is too large to hold in memory; set terrain.max_resolution");
        readX += win.col0;
        readY += win.row0;
        w = win.cols;
        h = win.rows;
    }
    if (gridOnly && lazyWarp) {
        // The trimmed warp's grid, and the height range of the source's valid cells (one streamed
        // pass), which bounds the warp's: bilinear and averaged values, and the membrane over
        // the holes, lie within the values around them.
        double minMax[2] = {0.0, 0.0};
        if (GDALComputeRasterMinMax(GDALGetRasterBand(heightSource, 1), FALSE, minMax) != CE_None)
            fail(path, withGdalReason("cannot read band 1"));
        double wgt[6];
        rd->GetGeoTransform(wgt);
        double u = 1.0;
        if (const OGRSpatialReference* outSrs = rd->GetSpatialRef(); outSrs && outSrs->GetLinearUnits() > 0.0)
            u = outSrs->GetLinearUnits();
        *gridOnly = {gridW, gridH, std::abs(wgt[1]) * u, std::abs(wgt[5]) * u,
                     minMax[0] * options.verticalScale, minMax[1] * options.verticalScale, true};
        return result;
    }
    double rgt[6] = {0, 1, 0, 0, 0, -1};
    if (hasGeoTransform) {
        rd->GetGeoTransform(rgt);
    } else {  // 1 m source cells, widened by any reduction (GDAL keeps no geotransform for it)
        rgt[1] = double(info.sourceWidth) / rd->GetRasterXSize();
        rgt[5] = -double(info.sourceHeight) / rd->GetRasterYSize();
    }
    GDALRasterBand* rband = rd->GetRasterBand(1);
    int rHasNodata = 0;
    const double rNodata = rband->GetNoDataValue(&rHasNodata);

    std::vector<float> heights;
    try {
        heights.resize(size_t(w) * size_t(h));
    } catch (const std::bad_alloc&) {
        fail(path, "raster " + std::to_string(w) + "x" + std::to_string(h) +
                       " is too large to hold in memory; set terrain.max_resolution");
    }
    if (rband->RasterIO(GF_Read, readX, readY, w, h, heights.data(), w, h, GDT_Float32, 0, 0, nullptr) !=
        CE_None)
        fail(path, withGdalReason("cannot read band 1"));

    // Metric units and the CRS of the grid read.
    double unit = 1.0;
    std::string crsWkt, crsName;
    int epsg = 0;
    if (const OGRSpatialReference* outSrs = rd->GetSpatialRef(); outSrs && !outSrs->IsEmpty()) {
        unit = outSrs->GetLinearUnits();
        if (!(unit > 0.0)) unit = 1.0;
        char* wkt = nullptr;
        outSrs->exportToWkt(&wkt);
        crsWkt = wkt ? wkt : "";
        CPLFree(wkt);
        crsName = srsName(*outSrs);
        epsg = srsEpsg(*outSrs);
    }
    // Everything is read: the last dataset goes before the trim and the void fill.
    rd = nullptr;
    rband = nullptr;
    work.reset();
    firstBand.reset();
    src.reset();

    std::vector<uint8_t> nodata(heights.size(), 0);
    const bool nodataIsNan = rHasNodata && std::isnan(rNodata);
    const float nodataF = float(rNodata);
    size_t nodataCount = 0;
    for (size_t i = 0; i < heights.size(); ++i) {
        const float v = heights[i];
        if ((rHasNodata && (nodataIsNan ? std::isnan(v) : v == nodataF))) {
            nodata[i] = 1;
            ++nodataCount;
        } else if (!std::isfinite(v)) {
            fail(path, "non-finite height at column " + std::to_string(i % w) + ", row " +
                           std::to_string(i / w) + "; heights must be finite numbers");
        }
    }

    if (nodataCount == heights.size()) fail(path, "every cell is nodata; nothing to import");

    if (nodataCount > 0) {
        try {
            const MembraneReport fill = fillVoids(heights, w, h, nodata);
            if (!fill.converged)
                info.warnings.push_back("nodata fill: the membrane solve stopped at its " +
                                        std::to_string(kMembraneMaxIterations) +
                                        "-iteration cap before reaching 0.1 mm in some hole");
        } catch (const DemError& e) {
            fail(path, e.what());
        }
    }

    // Metric cell sizes and the geographic origin of the footprint centre.
    const double cellX = std::abs(rgt[1]) * unit;
    const double cellZ = std::abs(rgt[5]) * unit;

    const double scale = options.verticalScale;
    if (!(scale > 0.0) || !std::isfinite(scale))
        fail(path, "vertical scale " + fmt(scale) + " must be finite and > 0");
    if (scale != 1.0)
        for (float& v : heights) v = float(v * scale);

    try {
        result.heightfield = Heightfield(w, h, cellX, cellZ, std::move(heights));
        result.heightfield.setNodataMask(nodataCount > 0 ? std::move(nodata)
                                                         : std::vector<uint8_t>{});
    } catch (const std::invalid_argument& e) {
        fail(path, e.what());
    }
    if (info.windowRead) result.heightfield.placeInGrid(gridW, gridH, readX - x0, readY - y0);
    GeoOrigin& geo = result.heightfield.geo;
    // The footprint centre: the whole grid's, for a window read alone.
    geo.easting = (rgt[0] + rgt[1] * (x0 + gridW * 0.5)) * unit;
    geo.northing = (rgt[3] + rgt[5] * (y0 + gridH * 0.5)) * unit;
    geo.height = 0.0;
    geo.crsWkt = crsWkt;
    geo.crsName = crsName;
    geo.epsg = epsg;
    if (!crsWkt.empty()) locateOnEarth(geo, unit);
    return result;
}

}  // namespace

DemImportResult importDem(const std::string& path, const DemImportOptions& options) {
    return importDemImpl(path, options, nullptr);
}

DemGrid demGrid(const std::string& path, const DemImportOptions& options) {
    DemImportOptions whole = options;
    whole.window.reset();
    DemGrid g;
    importDemImpl(path, whole, &g);
    return g;
}

}  // namespace terralux

namespace terralux {

namespace {

// Runs `read` on the path GDAL sees for an embedded raster, messages naming `name`.
template <class Read>
auto onMemoryRaster(const std::string& name, const unsigned char* bytes, size_t size, const Read& read) {
    registerDriversOnce();
    static std::atomic<unsigned> counter{0};
    const std::string vsiPath =
        "/vsimem/terralux-" + std::to_string(counter.fetch_add(1)) + "/" + name;
    // GDAL only reads the buffer; it does not take ownership (last argument FALSE).
    VSILFILE* f = VSIFileFromMemBuffer(vsiPath.c_str(), const_cast<GByte*>(bytes),
                                       vsi_l_offset(size), FALSE);
    if (!f) throw DemError(name + ": cannot map the embedded raster");
    VSIFCloseL(f);
    struct Unlink {
        std::string p;
        ~Unlink() { VSIUnlink(p.c_str()); }
    } unlink{vsiPath};
    try {
        return read(vsiPath);
    } catch (const DemError& e) {
        std::string msg = e.what();
        if (msg.rfind(vsiPath, 0) == 0) msg = name + msg.substr(vsiPath.size());
        throw DemError(msg);
    }
}

}  // namespace

DemImportResult importDemFromMemory(const std::string& name, const unsigned char* bytes,
                                    size_t size, const DemImportOptions& options) {
    return onMemoryRaster(name, bytes, size, [&](const std::string& path) {
        DemImportResult r = importDem(path, options);
        r.source.path = name;
        return r;
    });
}

DemGrid demGridFromMemory(const std::string& name, const unsigned char* bytes, size_t size,
                          const DemImportOptions& options) {
    return onMemoryRaster(name, bytes, size, [&](const std::string& path) { return demGrid(path, options); });
}

}  // namespace terralux
