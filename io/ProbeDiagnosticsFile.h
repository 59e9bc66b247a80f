#pragma once
// `<volume>.probes.json`, written by the bake beside `<volume>.shprobe`: the probe diagnostics
// that the file format has no room for (bake/ProbeDiagnostics.h), read back by `--render` and the
// viewport for the validity and interpolation-error views and the leaf overlay.
//
//   {
//     "format": "terralux-probe-diagnostics", "version": 1,
//     "volume": "<name>",                      the .shprobe stem
//     "probe_count": N, "grid_dims": [X, Y, Z] as in the .shprobe (a mismatch: stale sidecar)
//     "shprobe_fnv1a64": "<16 hex digits>"     FNV-1a 64 of the .shprobe's bytes (the same check)
//     "positions": [x, y, z, ...]              3N numbers, metres, engine space (mm precision)
//     "moved": [i, ...]                        probe indices moved up out of the terrain
//     "standard_error": [e, ...]               optional: N relative standard errors (1e-6)
//     "rejected": [x, y, z, ...]               probes placed inside the terrain (not in the file)
//     "leaves": [x, y, z, edge, ...]           adaptive octree leaves, min corner and edge
//     "error_map": {"size": [nx, nz], "origin": [x0, z0], "step": s, "height": h,
//                   "error": [...]}            nx·nz relative errors, x fastest, null = uncovered
//   }

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <span>
#include <string>

#include <glm/vec3.hpp>

#include "ShProbeFile.h"
#include "bake/ProbeDiagnostics.h"

namespace terralux {

class ProbeDiagnosticsError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// The sidecar's file name for a volume: "<name>.probes.json".
std::string probeDiagnosticsFileName(const std::string& volumeName);

// What ties a sidecar to its .shprobe: FNV-1a 64 of the file's bytes.
uint64_t shProbeDigest(std::span<const uint8_t> shprobeBytes);

std::string encodeProbeDiagnostics(const ProbeDiagnostics& d, const std::string& volumeName,
                                   const ShProbeGrid& grid);

// Parses and validates against the .shprobe it belongs to (probe count, grid dims and digest of
// its bytes). Every error message starts with `name`.
ProbeDiagnostics decodeProbeDiagnostics(const std::string& text, const std::string& name,
                                        const ShProbeGrid& grid, uint64_t shprobeDigest);

ProbeDiagnostics readProbeDiagnosticsFile(const std::filesystem::path& path, const ShProbeGrid& grid,
                                          uint64_t shprobeDigest);

}  // namespace terralux
