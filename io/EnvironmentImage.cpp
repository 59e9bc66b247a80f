#include "EnvironmentImage.h"

#include <cmath>
#include <filesystem>
#include <memory>

#include <OpenImageIO/imageio.h>

namespace terralux {

namespace {

// Opens the image and checks what its header can tell: there, readable, 2:1.
std::unique_ptr<OIIO::ImageInput> openEquirect(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw ImageError(path + ": no such file");
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
