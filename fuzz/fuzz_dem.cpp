// DEM import through GDAL's /vsimem/ (importDemFromMemory), one driver per build of this file:
// TERRALUX_FUZZ_DEM_NAME is the file name GDAL sees and TERRALUX_FUZZ_DEM_DRIVER the only file
// driver left registered, so each target explores one format (MEM stays: the import warps to it).
// SRTM .hgt files have fixed sizes (1201² or 3601² big-endian int16); for that driver the input
// is repeated to fill a 1201² tile, so small inputs still reach the import. Refusals are
// DemError; a raster that imports is a finite heightfield of at least 2 x 2 cells.

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <gdal_priv.h>

#include "DemImport.h"
#include "FuzzSupport.h"
#include "GdalSupport.h"

using namespace terralux;

namespace {

constexpr bool kHgt = std::string_view(TERRALUX_FUZZ_DEM_DRIVER) == "SRTMHGT";
constexpr size_t kHgtBytes = size_t(1201) * 1201 * 2;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    CPLSetConfigOption("GDAL_PAM_ENABLED", "NO");
    CPLSetConfigOption("GDAL_CACHEMAX", "64");
    CPLSetConfigOption("GDAL_NUM_THREADS", "1");
    gdal::registerDriversOnce();
    GDALDriverManager* drivers = GetGDALDriverManager();
    for (int i = drivers->GetDriverCount() - 1; i >= 0; --i) {
        GDALDriver* d = drivers->GetDriver(i);
        const std::string name = d->GetDescription();
        if (name != TERRALUX_FUZZ_DEM_DRIVER && name != "MEM") {
            drivers->DeregisterDriver(d);
            delete d;
        }
    }
    CPLSetErrorHandler(CPLQuietErrorHandler);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::vector<uint8_t> bytes(data, data + size);
    if (kHgt) {
        if (size == 0) return 0;
        bytes.resize(kHgtBytes);
        for (size_t i = size; i < kHgtBytes; ++i) bytes[i] = data[i % size];
    }
    DemImportOptions options;
    // A terrain.max_resolution, as projects for large DEMs set: keeps each run inside the time
    // limit and takes large rasters through the resampling path.
    options.maxResolution = 256;
    try {
        const DemImportResult r =
            importDemFromMemory(TERRALUX_FUZZ_DEM_NAME, bytes.data(), bytes.size(), options);
        const Heightfield& hf = r.heightfield;
        FUZZ_CHECK(hf.width() >= 2 && hf.depth() >= 2);
        FUZZ_CHECK(hf.width() <= 256 && hf.depth() <= 256);
        for (int z = 0; z < hf.depth(); ++z)
            for (int x = 0; x < hf.width(); ++x) FUZZ_CHECK(std::isfinite(hf.at(x, z)));
    } catch (const DemError&) {
    }
    return 0;
}
