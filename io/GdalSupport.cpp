#include "GdalSupport.h"

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
