#pragma once
// Byte-wise little-endian access for the binary formats, so neither host endianness nor
// alignment matters.

#include <bit>
#include <cstdint>
#include <vector>

namespace terralux::le {

inline uint32_t loadU32(const uint8_t* p) {
    return uint32_t{p[0]} | (uint32_t{p[1]} << 8) | (uint32_t{p[2]} << 16) | (uint32_t{p[3]} << 24);
}
inline float loadF32(const uint8_t* p) { return std::bit_cast<float>(loadU32(p)); }
inline int32_t loadI32(const uint8_t* p) { return std::bit_cast<int32_t>(loadU32(p)); }

inline void storeU32(std::vector<uint8_t>& out, uint32_t v) {
    out.push_back(static_cast<uint8_t>(v));
    out.push_back(static_cast<uint8_t>(v >> 8));
    out.push_back(static_cast<uint8_t>(v >> 16));
    out.push_back(static_cast<uint8_t>(v >> 24));
}
inline void storeF32(std::vector<uint8_t>& out, float v) { storeU32(out, std::bit_cast<uint32_t>(v)); }
inline void storeI32(std::vector<uint8_t>& out, int32_t v) { storeU32(out, std::bit_cast<uint32_t>(v)); }

}  // namespace terralux::le
