#include "GdalSupport.h"

#include <cmath>

#include <cpl_string.h>
#include <gdal_utils.h>

namespace terralux::gdal {
namespace {

template <typename NewOptions, typename FreeOptions, typename Run>
DatasetPtr runUtility(const std::vector<std::string>& args, NewOptions newOptions,
                      FreeOptions freeOptions, Run run, const char* what, std::string& why) {
    CPLStringList argv;
    for (const auto& a : args) argv.AddString(a.c_str());
    auto* options = newOptions(argv.List(), nullptr);
    if (!options) {
        why = withReason(std::string("invalid ") + what + " options");
        return nullptr;
    }
    int usageError = 0;
    GDALDatasetH out = run(options, &usageError);
    freeOptions(options);
    if (!out || usageError) {
        if (out) GDALClose(out);
        why = withReason(std::string(what) + " failed");
        return nullptr;
    }
    return DatasetPtr(out);
}

}  // namespace

std::string oversizedBlock(GDALDatasetH ds) {
    const int count = GDALGetRasterCount(ds);
    if (count < 1) return {};
    const char* interleave = GDALGetMetadataItem(ds, "INTERLEAVE", "IMAGE_STRUCTURE");
    const bool pixelInterleaved = count > 1 && interleave && EQUAL(interleave, "PIXEL");
    int cellBytes = 0;  // of one cell in a block of band 1: every band's samples when interleaved
    for (int b = 1; b <= (pixelInterleaved ? count : 1); ++b)
        cellBytes += std::max(1, GDALGetDataTypeSizeBytes(GDALGetRasterDataType(GDALGetRasterBand(ds, b))));
    const auto check = [&](GDALRasterBandH band, const std::string& what, int bytesPerCell,
                           bool interleaved) -> std::string {
        int bw = 0, bh = 0;
        GDALGetBlockSize(band, &bw, &bh);
        const double bytes = double(bw) * double(bh) * double(bytesPerCell);
        if (bytes <= kMaxBlockBytes) return {};
        return "one block of " + what + " decodes to " + fmt(std::round(bytes / (1024.0 * 1024.0))) + " MiB (" +
               std::to_string(bw) + " x " + std::to_string(bh) + " cells x " + std::to_string(bytesPerCell) +
               (bytesPerCell == 1 ? " byte" : " bytes") + (interleaved ? ": " + std::to_string(count) + " bands interleaved by pixel" : "") +
               "); at most " + fmt(kMaxBlockBytes / (1024.0 * 1024.0)) +
               " MiB; rewrite it tiled (gdal_translate -co TILED=YES" +
               (interleaved ? " -co INTERLEAVE=BAND)" : ")");
    };
    // Band 1, its overviews (which a reduction may read instead), and a mask stored for the whole
    // dataset (which resampling reads beside the heights) with its overviews.
    GDALRasterBandH band = GDALGetRasterBand(ds, 1);
    std::string found = check(band, "band 1", cellBytes, pixelInterleaved);
    for (int o = 0; found.empty() && o < GDALGetOverviewCount(band); ++o)
        found = check(GDALGetOverview(band, o), "band 1's overview " + std::to_string(o + 1), cellBytes,
                      pixelInterleaved);
    if (found.empty() && GDALGetMaskFlags(band) == GMF_PER_DATASET) {
        GDALRasterBandH mask = GDALGetMaskBand(band);
        found = check(mask, "the mask", 1, false);
        for (int o = 0; found.empty() && o < GDALGetOverviewCount(mask); ++o)
            found = check(GDALGetOverview(mask, o), "the mask's overview " + std::to_string(o + 1), 1, false);
    }
    return found;
}

DatasetPtr warp(GDALDatasetH src, const std::vector<std::string>& args, std::string& why) {
    return runUtility(
        args, GDALWarpAppOptionsNew, GDALWarpAppOptionsFree,
        [&](GDALWarpAppOptions* o, int* usage) {
            GDALDatasetH srcs[1] = {src};
            return GDALWarp("", nullptr, 1, srcs, o, usage);
        },
        "reprojection", why);
}

DatasetPtr translate(GDALDatasetH src, const std::vector<std::string>& args, std::string& why) {
    return runUtility(
        args, GDALTranslateOptionsNew, GDALTranslateOptionsFree,
        [&](GDALTranslateOptions* o, int* usage) { return GDALTranslate("", src, o, usage); },
        "resampling", why);
}

}  // namespace terralux::gdal
