#include "ImageFile.h"

#include <algorithm>
#include <cmath>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "AtomicFile.h"
#include "EnvironmentImage.h"
#include "scene/ImageCodes.h"

namespace terralux {

ImageEncoding encodingFor(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext == ".exr" ? ImageEncoding::LinearFloat : ImageEncoding::Display8;
}

namespace {

// `data`: width * height * 4 samples of `type` (FLOAT or UINT8), written as that type.
void writeSamples(const std::filesystem::path& path, uint32_t width, uint32_t height, size_t count,
                  OIIO::TypeDesc type, const void* data) {
    if (count != size_t(width) * height * 4)
        throw ImageError(path.string() + ": image data does not match " + std::to_string(width) +
                         "x" + std::to_string(height));
    // The temporary keeps the extension so OpenImageIO picks the format from it.
    std::filesystem::path tmp = temporarySibling(path);
    tmp += path.extension();
    auto out = OIIO::ImageOutput::create(path.string());
    if (!out)
        throw ImageError(path.string() + ": no image writer for this extension (" +
                         OIIO::geterror() + "); use .png or .exr");
    OIIO::ImageSpec spec(int(width), int(height), 4, type);
    // OpenImageIO stamps an EXR with the time of writing unless DateTime is given; an empty one
    // keeps the file the same bytes on every run, like every other output.
    if (type == OIIO::TypeDesc::FLOAT) spec.attribute("DateTime", "");
    if (!out->open(tmp.string(), spec) || !out->write_image(type, data) || !out->close()) {
        std::string why = out->geterror();
        std::replace(why.begin(), why.end(), '\n', ' ');
        std::error_code ec;
        std::filesystem::remove(tmp, ec);
        throw FileWriteError(path.string() + ": cannot write (" + why + ")");
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
        const std::string reason = ec.message();
        std::filesystem::remove(tmp, ec);
        throw FileWriteError(path.string() + ": cannot replace (" + reason + ")");
    }
}

}  // namespace

void writeImage(const std::filesystem::path& path, uint32_t width, uint32_t height,
                const std::vector<float>& rgba) {
    if (encodingFor(path) == ImageEncoding::LinearFloat) {
        writeSamples(path, width, height, rgba.size(), OIIO::TypeDesc::FLOAT, rgba.data());
        return;
    }
    std::vector<uint8_t> bytes(rgba.size());
    for (size_t i = 0; i < rgba.size(); ++i) bytes[i] = unitToByte(rgba[i]);
    writeSamples(path, width, height, bytes.size(), OIIO::TypeDesc::UINT8, bytes.data());
}

void writeImage(const std::filesystem::path& path, uint32_t width, uint32_t height,
                const std::vector<uint8_t>& bytes) {
    if (encodingFor(path) == ImageEncoding::LinearFloat)
        throw ImageError(path.string() + ": 8-bit samples cannot be written as EXR, which holds scene-linear "
                                         "floats; use .png");
    writeSamples(path, width, height, bytes.size(), OIIO::TypeDesc::UINT8, bytes.data());
}

std::vector<uint8_t> encodePng(uint32_t width, uint32_t height, int channels,
                               const std::vector<uint8_t>& samples) {
    if (samples.size() != size_t(width) * height * size_t(channels))
        throw ImageError("PNG encoding: data does not match " + std::to_string(width) + "x" +
                         std::to_string(height) + "x" + std::to_string(channels));
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput proxy(bytes);
    auto out = OIIO::ImageOutput::create("png");
    OIIO::ImageSpec spec(int(width), int(height), channels, OIIO::TypeDesc::UINT8);
    if (!out || !out->set_ioproxy(&proxy) || !out->open("memory.png", spec) ||
        !out->write_image(OIIO::TypeDesc::UINT8, samples.data()) || !out->close()) {
        std::string why = out ? out->geterror() : OIIO::geterror();
        std::replace(why.begin(), why.end(), '\n', ' ');
        throw ImageError("PNG encoding failed (" + why + ")");
    }
    return bytes;
}

std::vector<float> readImageRgba(const std::filesystem::path& path, uint32_t& width,
                                 uint32_t& height) {
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) throw ImageError(path.string() + ": cannot open (" + OIIO::geterror() + ")");
    const OIIO::ImageSpec& spec = in->spec();
    width = uint32_t(spec.width);
    height = uint32_t(spec.height);
    const int ch = spec.nchannels;
    std::vector<float> px(size_t(width) * height * size_t(ch));
    if (!in->read_image(0, 0, 0, ch, OIIO::TypeDesc::FLOAT, px.data()))
        throw ImageError(path.string() + ": cannot read (" + in->geterror() + ")");
    std::vector<float> rgba(size_t(width) * height * 4, 1.0f);
    for (size_t i = 0; i < size_t(width) * height; ++i)
        for (int c = 0; c < std::min(ch, 4); ++c) rgba[i * 4 + size_t(c)] = px[i * size_t(ch) + size_t(c)];
    return rgba;
}

}  // namespace terralux
