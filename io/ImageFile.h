#pragma once
// Rendered images out through OpenImageIO: 8-bit PNG of display-encoded values, or float EXR of
// scene-linear ones. Written to a temporary sibling and renamed when whole.

#include <cstdint>
#include <filesystem>
#include <vector>

namespace terralux {

enum class ImageEncoding { Display8, LinearFloat };

// rgba: width * height * 4 floats, row 0 at the top. The encoding follows the extension:
// .exr -> LinearFloat (half-free float32 RGBA), anything else (.png, .tif, ...) -> Display8.
// Throws ImageError (EnvironmentImage.h) for data or an extension it cannot encode, and
// FileWriteError (AtomicFile.h) when the file cannot be written; both name the file and the reason.
void writeImage(const std::filesystem::path& path, uint32_t width, uint32_t height,
                const std::vector<float>& rgba);
// bytes: width * height * 4 8-bit codes (unitToByte, scene/ImageCodes.h), row 0 at the top,
// written as they are; an .exr path is refused (ImageError).
void writeImage(const std::filesystem::path& path, uint32_t width, uint32_t height,
                const std::vector<uint8_t>& bytes);
ImageEncoding encodingFor(const std::filesystem::path& path);

// Encodes 8-bit samples (width * height * channels, row 0 at the top) as a PNG file's bytes, in
// memory. Throws ImageError when the encoder fails.
std::vector<uint8_t> encodePng(uint32_t width, uint32_t height, int channels,
                               const std::vector<uint8_t>& samples);

// Reads an image as RGBA float (8-bit files scaled to [0, 1]); for tests and tools.
std::vector<float> readImageRgba(const std::filesystem::path& path, uint32_t& width,
                                 uint32_t& height);

}  // namespace terralux
