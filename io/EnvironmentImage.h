#pragma once
// Equirectangular HDR skies through OpenImageIO (Radiance .hdr, OpenEXR, anything OIIO reads).

#include <stdexcept>
#include <string>
#include <vector>

namespace terralux {

class ImageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct RgbImage {
    int width = 0;
    int height = 0;
    std::vector<float> rgb;  // width * height * 3, row 0 at the top
};

// Reads the first three channels as linear float RGB (a one-channel image is grey). Throws
// ImageError naming the file and the problem: missing, unreadable, not 2:1, negative or
// non-finite texels.
RgbImage readEquirectImage(const std::string& path);
// The checks of the header alone (missing, unreadable, not 2:1), without reading the pixels.
void checkEquirectImage(const std::string& path);

}  // namespace terralux
