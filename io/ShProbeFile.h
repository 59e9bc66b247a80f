#pragma once
// Reader and writer for `.shprobe` version 1: a regular grid of cells, each pointing at one of a
// list of order-2 spherical-harmonic probes (9 RGB coefficients each). Little-endian throughout.
//
//   offset  size        field
//   0       4           uint32 magic 0x52485053 (bytes 53 50 48 52, "SPHR")
//   4       4           uint32 version = 1
//   8       4           uint32 probe count
//   12..20  4 each      uint32 grid dims X, Y, Z (cells)
//   24..32  4 each      float grid origin X, Y, Z (engine space, min corner)
//   36      4           float grid spacing (cell edge, metres)
//   40      4           float default SH scale
//   44      4           float default ambient term
//   48      count*160   probe records: 9 vec4 (RGB in xyz, w = 0), float scale (144),
//                       float ambient (148), 8 zero bytes (152..159)
//   after   X*Y*Z*4     int32 occupancy, cell x + y*X + z*X*Y -> probe index, -1 = no probe

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace terralux {

struct ShProbeRecord {
    std::array<glm::vec3, 9> coeffs{};  // coefficient k as RGB
    float scale = 1.0f;
    float ambient = 0.1f;

    bool operator==(const ShProbeRecord&) const = default;
};

struct ShProbeGrid {
    glm::uvec3 dims{1, 1, 1};
    glm::vec3 origin{0};  // min corner
    float spacing = 1.0f;
    float defaultScale = 1.0f;
    float defaultAmbient = 0.1f;
    std::vector<ShProbeRecord> probes;
    std::vector<int32_t> occupancy;  // dims.x*dims.y*dims.z entries, -1 = no probe

    // Flat occupancy index x + y*dimX + z*dimX*dimY; no bounds check.
    size_t cellIndex(uint32_t x, uint32_t y, uint32_t z) const;
    // 48 + 160*count + 4*cells; saturates at UINT64_MAX when that is not representable.
    uint64_t fileSize() const;

    bool operator==(const ShProbeGrid&) const = default;
};

class ShProbeError : public std::runtime_error {
public:
    using runtime_error::runtime_error;
};

// Serialises exactly per the layout above, independent of host endianness. Throws ShProbeError
// if the grid breaks any rule the reader enforces, or if occupancy.size() != cell count.
std::vector<uint8_t> encodeShProbe(const ShProbeGrid& grid);

// Parses and validates; `name` prefixes every error message.
ShProbeGrid decodeShProbe(std::span<const uint8_t> bytes, const std::string& name);

// Atomic: writes "<path>.tmp-<random>" beside the target, then renames it over the target. On
// any failure the temporary is removed, an existing target is left untouched, and it throws.
void writeShProbeFile(const std::filesystem::path& path, const ShProbeGrid& grid);

// Error messages start with the file path. `bytes`, when given, receives the file as read.
ShProbeGrid readShProbeFile(const std::filesystem::path& path, std::vector<uint8_t>* bytes = nullptr);

}  // namespace terralux
