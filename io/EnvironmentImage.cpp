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

// The widest sky read: 32 768 x 16 384, beyond the largest published equirectangular skies (24K),
// whose RGBA floats alone would take 8 GiB.
constexpr int64_t kMaxEquirectWidth = 32768;

// An OpenEXR header is a list of attributes (name, type, 32-bit size, value; the OpenEXR file
// layout, "Header Attributes"). OpenEXR 3.1 allocates whatever an attribute's value claims before
// it reads it (a string or an unknown type: its size; a preview: width x height x 4; a string
// vector: each string's length), so a 1 KB file can make it allocate and fill gigabytes. Walk the
// header as OpenEXR's Header::readFrom does (names and types read up to 255 bytes; fixed-size
// types and channel lists read by their own layout, whatever size they declare) and refuse any
// claim past the end of the file before handing the file over.
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
        while (out.size() < 255 && in.get(c) && c != '\0') out.push_back(c);
        return bool(in);
    };
    auto readU32 = [&](uint32_t& v) {
        unsigned char b[4];
        if (!in.read(reinterpret_cast<char*>(b), 4)) return false;
        v = uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
        return true;
    };
    auto remaining = [&] {
        const std::streamoff at = in.tellg();
        return at < 0 ? uint64_t(0) : fileBytes - std::min(uint64_t(at), fileBytes);
    };
    auto refuse = [&](const std::string& name, uint64_t bytes) {
        throw ImageError(path + ": EXR header attribute '" + name + "' claims " + std::to_string(bytes) +
                         " bytes, past the end of the file (" + std::to_string(fileBytes) + " bytes)");
    };
    // Bytes OpenEXR reads for a fixed-size type, whatever the attribute's size field says.
    static const std::pair<const char*, int> kFixed[] = {
        {"box2i", 16}, {"box2f", 16}, {"compression", 1}, {"chromaticities", 32},
        {"deepImageState", 1}, {"double", 8}, {"envmap", 1}, {"float", 4}, {"int", 4},
        {"keycode", 28}, {"lineOrder", 1}, {"m33d", 72}, {"m33f", 36}, {"m44d", 128},
        {"m44f", 64}, {"rational", 8}, {"tiledesc", 9}, {"timecode", 8}, {"v2d", 16},
        {"v2f", 8}, {"v2i", 8}, {"v3d", 24}, {"v3f", 12}, {"v3i", 12}};
    std::string name, type, channel;
    while (readName(name) && !name.empty()) {
        uint32_t size = 0;
        if (!readName(type) || !readU32(size) || int32_t(size) < 0) return;
        if (name == "dataWindow" && type == "box2i") {
            // OpenEXR sizes its line buffers by the window's width before it reads a pixel: refuse
            // a window no equirectangular sky has (the rule openEquirect applies once it is open)
            // while the width is still only a number.
            uint32_t box[4];
            for (uint32_t& v : box)
                if (!readU32(v)) return;
            const int64_t w = int64_t(int32_t(box[2])) - int32_t(box[0]) + 1;
            const int64_t h = int64_t(int32_t(box[3])) - int32_t(box[1]) + 1;
            if (w < 2 || h < 1 || w != 2 * h || w > kMaxEquirectWidth)
                throw ImageError(path + ": EXR data window " + std::to_string(w) + "x" + std::to_string(h) +
                                 " is not an equirectangular image (width twice the height, at most " +
                                 std::to_string(kMaxEquirectWidth) + ")");
        } else if (const auto* f = std::find_if(std::begin(kFixed), std::end(kFixed),
                                                [&](const auto& t) { return type == t.first; });
                   f != std::end(kFixed)) {
            in.seekg(f->second, std::ios::cur);
        } else if (type == "chlist") {
            // Channels until an empty name: each a name and 16 bytes of layout.
            while (readName(channel) && !channel.empty()) in.seekg(16, std::ios::cur);
        } else if (type == "preview") {
            uint32_t w = 0, h = 0;
            if (!readU32(w) || !readU32(h)) return;
            if (uint64_t(w) * h * 4 > remaining()) refuse(name, uint64_t(w) * h * 4);
            in.seekg(std::streamoff(uint64_t(w) * h * 4), std::ios::cur);
        } else if (type == "stringvector") {
            if (uint64_t(size) > remaining()) refuse(name, size);
            const std::streamoff end = in.tellg() + std::streamoff(size);
            for (uint32_t len = 0; in.tellg() < end && readU32(len);) {
                if (uint64_t(len) > remaining()) refuse(name, len);
                in.seekg(std::streamoff(len), std::ios::cur);
            }
        } else {
            // string, floatvector, bytes, idmanifest and unknown (opaque) types: `size` bytes.
            if (uint64_t(size) > remaining()) refuse(name, size);
            in.seekg(std::streamoff(size), std::ios::cur);
        }
        if (!in) return;
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
    if (spec.width < 2 || spec.height < 1 || spec.width != 2 * spec.height || spec.width > kMaxEquirectWidth)
        throw ImageError(path + ": " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                         " is not an equirectangular image (width twice the height, at most " +
                         std::to_string(kMaxEquirectWidth) + ")");
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
