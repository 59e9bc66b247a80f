#include "EnvironmentImage.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <string>
#include <filesystem>
#include <memory>

#include <OpenImageIO/imageio.h>

namespace terralux {

namespace {

// An OpenEXR header is a list of attributes (name, type, 32-bit size, value; the OpenEXR file
// layout, "Header Attributes"). OpenEXR 3.1 allocates and fills whatever size an attribute claims
// before it reads the value, so a 1 KB file claiming a 500 MB string takes seconds and the
// memory: refuse a size past the end of the file before handing the file over.
void checkExrHeader(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    unsigned char magic[8] = {};
    if (!in.read(reinterpret_cast<char*>(magic), 8) || magic[0] != 0x76 || magic[1] != 0x2f ||
        magic[2] != 0x31 || magic[3] != 0x01)
        return;
    std::error_code ec;
    const uint64_t fileBytes = std::filesystem::file_size(path, ec);
    if (ec) return;
    auto readName = [&](std::string& out) {
        out.clear();
        char c;
        while (in.get(c) && c != '\0') {
            if (out.size() >= 255) return false;
            out.push_back(c);
        }
        return bool(in);
    };
    std::string name, type;
    while (readName(name) && !name.empty()) {
        unsigned char size[4];
        if (!readName(type) || !in.read(reinterpret_cast<char*>(size), 4)) return;
        const uint32_t bytes = uint32_t(size[0]) | uint32_t(size[1]) << 8 | uint32_t(size[2]) << 16 |
                               uint32_t(size[3]) << 24;
        const uint64_t at = uint64_t(in.tellg());
        if (uint64_t(bytes) > fileBytes - std::min(at, fileBytes))
            throw ImageError(path + ": EXR header attribute '" + name + "' claims " + std::to_string(bytes) +
                             " bytes, past the end of the file (" + std::to_string(fileBytes) + " bytes)");
        in.seekg(std::streamoff(bytes), std::ios::cur);
    }
}

// Opens the image and checks what its header can tell: there, readable, 2:1.
std::unique_ptr<OIIO::ImageInput> openEquirect(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw ImageError(path + ": no such file");
    checkExrHeader(path);
    auto in = OIIO::ImageInput::open(path);
    if (!in) {
        std::string why = OIIO::geterror();
        for (char& c : why)
            if (c == '\n') c = ' ';
        throw ImageError(path + ": not an image OpenImageIO can read (" + why + ")");
    }
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width < 2 || spec.height < 1 || spec.width != 2 * spec.height)
        throw ImageError(path + ": " + std::to_string(spec.width) + "x" +
                         std::to_string(spec.height) +
                         " is not an equirectangular image (width must be twice the height)");
    return in;
}

}  // namespace

void checkEquirectImage(const std::string& path) { openEquirect(path)->close(); }

RgbImage readEquirectImage(const std::string& path) {
    auto in = openEquirect(path);
    const OIIO::ImageSpec& spec = in->spec();
    const int channels = spec.nchannels;
    std::vector<float> pixels(size_t(spec.width) * spec.height * channels);
    if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels.data())) {
        std::string why = in->geterror();
        for (char& c : why)
            if (c == '\n') c = ' ';
        throw ImageError(path + ": cannot read pixels (" + why + ")");
    }
    in->close();
    RgbImage img{spec.width, spec.height, std::vector<float>(size_t(spec.width) * spec.height * 3)};
    for (size_t i = 0; i < size_t(spec.width) * spec.height; ++i)
        for (int c = 0; c < 3; ++c) {
            const float v = pixels[i * channels + std::min(c, channels - 1)];
            if (!std::isfinite(v) || v < 0.0f)
                throw ImageError(path + ": texel " + std::to_string(i % spec.width) + "," +
                                 std::to_string(i / spec.width) +
                                 " is negative or not finite; sky radiance must be >= 0");
            img.rgb[i * 3 + c] = v;
        }
    return img;
}

}  // namespace terralux
