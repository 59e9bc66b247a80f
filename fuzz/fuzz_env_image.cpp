// HDR/EXR sky loader (readEquirectImage). It takes a path and OpenImageIO 2.4's readers open
// files by name, so each input is written to a temporary file first: named .exr when it starts
// with the OpenEXR magic, .hdr otherwise. OpenImageIO is kept to the reader the extension names
// (try_all_readers off) and to one thread. Refusals are ImageError; an image that loads is 2:1
// with finite, non-negative texels.

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <OpenImageIO/imageio.h>

#include "EnvironmentImage.h"
#include "FuzzSupport.h"

using namespace terralux;
namespace fs = std::filesystem;

namespace {

fs::path g_dir;

void removeDir() {
    std::error_code ec;
    fs::remove_all(g_dir, ec);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    OIIO::attribute("threads", 1);
    OIIO::attribute("exr_threads", 1);
    OIIO::attribute("try_all_readers", 0);
    g_dir = fs::temp_directory_path() / ("terralux-fuzz-env-" + std::to_string(getpid()));
    fs::create_directories(g_dir);
    std::atexit(removeDir);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const uint8_t kExrMagic[4] = {0x76, 0x2f, 0x31, 0x01};
    const bool exr = size >= 4 && std::equal(kExrMagic, kExrMagic + 4, data);
    const fs::path file = g_dir / (exr ? "sky.exr" : "sky.hdr");
    {
        std::ofstream out(file, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
    }
    try {
        checkEquirectImage(file.string());
        const RgbImage img = readEquirectImage(file.string());
        FUZZ_CHECK(img.width == 2 * img.height && img.height >= 1);
        FUZZ_CHECK(img.rgb.size() == size_t(img.width) * img.height * 3);
        for (float v : img.rgb) FUZZ_CHECK(std::isfinite(v) && v >= 0.0f);
    } catch (const ImageError&) {
    }
    std::error_code ec;
    fs::remove(file, ec);
    return 0;
}
