#pragma once
// The reflection probes' files (docs/formats.md, "Reflection probes"):
//
// `.rprobe` version 1, one file per probe set, little-endian throughout:
//   offset  size   field
//   0       4      uint32 magic 0x50524C54 (bytes 54 4C 52 50, "TLRP")
//   4       4      uint32 version = 1
//   8       4      uint32 encoding: 0 faces, 1 cubemap
//   12      4      uint32 probe count (= nx · nz, at most 256)
//   16, 20  4 each uint32 grid nx, nz
//   24      4      uint32 face size: cubemap texels a side of mip 0 (a power of two); faces 0
//   28      4      uint32 mip count: cubemap log2(face size) − 1 (down to 4×4); faces 1
//   32, 36  4 each float (x, z) of probe 0
//   40, 44  4 each float spacing (x, z), 0 on a one-probe axis
//   48, 52  4 each float cell size (x, z)
//   56      4      float fallback blend distance (metres)
//   60      4      float strength
//   64      ...    per probe, in scene order (row-major, x fastest):
//                    uint32 id, float position xyz, float box half extents xyz, float intensity,
//                    6 × RGB float face colours (+X, −X, +Y, −Y, +Z, −Z): 104 bytes; then, cubemap
//                    only, every mip level from 0, every face, rows top to bottom: RGB float texels.
//
// simvx box records (seed 002): `probes.simvx.bin`, the desktop SSBO image, and
// `probes.simvx.wire`, the web stream (layout in ReflectionBoxRecords below).

#include <cstdint>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "bake/ReflectionBake.h"

namespace terralux {

class ReflectionFileError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

inline constexpr uint32_t kRprobeMagic = 0x50524C54u;
inline constexpr size_t kRprobeHeaderBytes = 64;
inline constexpr size_t kRprobeProbeBytes = 104;  // before the texels
// File names within the bake's reflection/ folder.
inline constexpr const char* kReflectionProbeFile = "probes.rprobe";
inline constexpr const char* kSimvxDesktopFile = "probes.simvx.bin";
inline constexpr const char* kSimvxWireFile = "probes.simvx.wire";

// Throws ReflectionFileError for a set the reader would refuse.
std::vector<uint8_t> encodeReflectionProbes(const ReflectionProbeSet& set);
// `name` begins every error message.
ReflectionProbeSet decodeReflectionProbes(std::span<const uint8_t> bytes, const std::string& name);
ReflectionProbeSet readReflectionProbeFile(const std::filesystem::path& path);

// Seed 002's box records. One record is 48 bytes, three std430 vec4 of float:
//   centre_slice           xyz the capture position, w the cube-array layer slot·6 (0 on the wire)
//   half_extent_intensity  xyz the box's half extents, w the intensity (strength)
//   flags                  x 1 (box projection), y the blend distance, z the scheduling bits
//                          (4 = update requested: a baked probe), w 0
// Desktop: a 16-byte header (uint32 live count, 12 zero bytes), records at 16 + slot·48, 400
// bytes whatever the count. Wire: per probe a uint32 stable id, then the record (52 bytes).
inline constexpr size_t kSimvxRecordBytes = 48;
inline constexpr size_t kSimvxDesktopBytes = 16 + kSimvxMaxProbes * kSimvxRecordBytes;
inline constexpr uint32_t kSimvxSchedUpdateRequested = 4;

struct ReflectionBoxRecords {
    std::vector<uint8_t> desktop;     // kSimvxDesktopBytes
    std::vector<uint8_t> wire;        // 52 per exported probe
    std::vector<uint32_t> exported;   // ids, in slot order
    size_t total = 0;                 // probes in the set
};
// The probes (indices in scene order) the records carry: `subset` sorted, or the first 8 of
// `count` when it is empty. Throws PlacementError naming reflection_probes.simvx_subset for more
// than 8 indices, an index out of the grid, or one given twice.
std::vector<int> simvxProbes(const std::vector<int>& subset, size_t count);
// The records of the probes `subset` names (indices in scene order, at most 8, each below the
// set's count), or of the first 8 when it is empty; slots follow scene order. Throws
// PlacementError naming reflection_probes.simvx_subset for a bad subset.
ReflectionBoxRecords encodeBoxRecords(const ReflectionProbeSet& set, const std::vector<int>& subset);

}  // namespace terralux
