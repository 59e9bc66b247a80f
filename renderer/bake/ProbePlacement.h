#pragma once
// Where the probes of a volume go, which are valid, and the .shprobe grid they are written into.

#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "scene/SceneDescription.h"
#include "terrain/Heightfield.h"

namespace terralux {

class PlacementError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct ProbeLayout {
    std::vector<glm::vec3> positions;  // every placed probe, valid or not, in placement order
    std::vector<uint8_t> valid;        // 0: inside the terrain, no SH, no occupancy cell
    // Terrain grids: (nx, 1, nz); box grids: (nx, ny, nz). Placement order is x fastest.
    std::array<int, 3> probeDims{1, 1, 1};
    glm::vec3 spacing{0.0f};           // between neighbouring probes per axis (0 on a 1-wide axis)
    float fallbackBlendDistance = 0.0f;

    // The .shprobe occupancy grid: cubic cells of `cellSize` from `origin` (min corner).
    std::array<uint32_t, 3> cellDims{1, 1, 1};
    glm::vec3 cellOrigin{0.0f};
    float cellSize = 1.0f;
    // cell -> index into positions (not yet compacted to valid probes), -1 = none.
    std::vector<int32_t> cellProbe;

    size_t validCount() const;
};

// Exact lowest and highest point of the triangle surface (and its skirt) over the rectangle
// [x0, x1] × [z0, z1]: a piecewise-linear surface takes its extremes at the mesh vertices inside
// the rectangle and where the rectangle's edges cross grid lines and cell diagonals.
struct SurfaceRange {
    float lo = INFINITY, hi = -INFINITY;
};
SurfaceRange surfaceRange(const Heightfield& hf, double x0, double x1, double z0, double z1);

// Largest occupancy grid a volume may write (cells); bigger layouts are refused with a message.
inline constexpr uint64_t kMaxOccupancyCells = uint64_t(64) << 20;

// Throws PlacementError naming the volume setting, the value and the rule.
ProbeLayout placeProbes(const ProbeVolumeSettings& volume, const Heightfield& hf);

}  // namespace terralux
