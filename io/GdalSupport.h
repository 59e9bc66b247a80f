#pragma once
// What every GDAL reader in io/ shares: driver registration, quiet errors folded into our
// messages, and datasets that close themselves. Internal to io/ (nothing outside links GDAL).

#include <algorithm>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <gdal.h>

namespace terralux::gdal {

// Also caps GDAL's block cache at 4 MB unless GDAL_CACHEMAX says otherwise: every reader here
// reads its raster once, front to back, so a cache buys nothing, and GDAL's default (5 % of RAM)
// kept a DEM's blocks alive through the import (bench_bake_memory: 8 MB of a bake's peak).
inline void registerDriversOnce() {
    static std::once_flag once;
    std::call_once(once, [] {
        GDALAllRegister();
        if (!CPLGetConfigOption("GDAL_CACHEMAX", nullptr)) GDALSetCacheMax64(GIntBig(4) << 20);
    });
}

// GDAL reports through a global handler; keep its chatter off the user's terminal and fold its
// last message into ours.
class QuietErrors {
public:
    QuietErrors() {
        CPLPushErrorHandler(CPLQuietErrorHandler);
        CPLErrorReset();
    }
    ~QuietErrors() { CPLPopErrorHandler(); }
    QuietErrors(const QuietErrors&) = delete;
    QuietErrors& operator=(const QuietErrors&) = delete;
    static std::string last() {
        std::string msg = CPLGetLastErrorMsg();
        std::replace(msg.begin(), msg.end(), '\n', ' ');
        return msg;
    }
};

struct DatasetCloser {
    void operator()(GDALDatasetH ds) const {
        if (ds) GDALClose(ds);
    }
};
using DatasetPtr = std::unique_ptr<void, DatasetCloser>;

// "what (GDAL's last message)", or just "what" when GDAL said nothing.
inline std::string withReason(const std::string& what) {
    const std::string reason = QuietErrors::last();
    return reason.empty() ? what : what + " (" + reason + ")";
}

// A number as GDAL's utilities read it back exactly.
inline std::string fmt(double v) {
    std::ostringstream s;
    s.precision(17);
    s << v;
    return s.str();
}

// GDAL decodes a raster a block at a time, and a pixel-interleaved block holds every band's
// samples, so reading one band allocates block width x block height x the bytes of all bands at
// once. A block of band 1, of its overviews, or of a mask stored for the dataset may take at most
// what the largest height grid the DEM import accepts takes (256 Mi cells of 4 bytes). Empty when
// all are within that; otherwise what the first too large one would take and the rule, for the
// caller to prefix with the file. Reads no pixel.
inline constexpr double kMaxBlockBytes = 1024.0 * 1024 * 1024;
std::string oversizedBlock(GDALDatasetH ds);

// gdalwarp / gdal_translate (their library form) on `src`, with command-line `args`; the result
// is what `-of` names (MEM in memory). Null on failure, with `why` saying what failed and GDAL's
// reason.
DatasetPtr warp(GDALDatasetH src, const std::vector<std::string>& args, std::string& why);
DatasetPtr translate(GDALDatasetH src, const std::vector<std::string>& args, std::string& why);

}  // namespace terralux::gdal
