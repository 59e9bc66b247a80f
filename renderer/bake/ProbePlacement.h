#pragma once
// Where the probes of a volume go, which are valid, and the .shprobe grid they are written into.

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
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

// One leaf of an adaptive octree, in units of the minimum cell: it covers the cells
// [x, x + 2^level) × [y, y + 2^level) × [z, z + 2^level) of the .shprobe grid.
struct OctreeLeaf {
    uint32_t x = 0, y = 0, z = 0;
    uint8_t level = 0;
    uint32_t edge() const { return 1u << level; }
    bool operator==(const OctreeLeaf&) const = default;
};

// What happened to the probe of a leaf (docs/lighting.md: never a probe inside the terrain).
enum class LeafProbe : uint8_t {
    Centre,    // at the leaf centre, above the terrain
    Moved,     // a minimum-size leaf whose centre is inside: moved up, within max_move_share
    // A minimum-size leaf whose centre is too deep inside to move: no probe of its own; its cell,
    // partly above the terrain, points at the first probe above it in its column (as a
    // terrain-following grid does), so objects on the ground there still find a probe.
    Borrowed,
    Dropped,   // the same with no probe above it in the box: its cell holds -1
};

// The adaptive octree behind a layout, with its resolved settings; or, for a surface volume,
// its quadtree (`surface`: leaves are squares with y = 0, no band, no moves).
struct AdaptiveOctree {
    bool surface = false;
    double heightOffset = 0.0;         // surface: the probes' height above the ground
    double minCell = 1.0, maxCell = 1.0, surfaceBand = 0.0;
    double surfaceCell = 1.0;          // the size the surface band forces cells down to
    int levels = 0;                    // maxCell = minCell * 2^levels
    std::vector<OctreeLeaf> leaves;    // leaves[i] holds ProbeLayout::positions[i]
    std::vector<LeafProbe> probe;      // per leaf
    size_t moved = 0, borrowed = 0, dropped = 0;
    // Cells that were split because their centre lay inside the terrain (they overlap the
    // surface band too, so the band rule alone would have split them).
    size_t splitForInside = 0;
    // Probes a uniform grid at the minimum cell size over the same box would hold: every cell
    // whose centre is above the terrain (surface: every minimum square of the footprint).
    size_t uniformProbes = 0;
};

// Seed 000's fallback_blend_distance when it is unset, one rule for diffuse and reflection grids:
// 2 * min(spacing_x, spacing_z) over the horizontal axes, where an axis that holds a single probe
// (spacing 0) takes as its spacing the width that probe stands for, `extent` along that axis (the
// footprint's extent for a terrain grid or a reflection grid, the cell for a box). docs/lighting.md.
float defaultFallbackBlendDistance(glm::vec2 spacing, glm::vec2 extent);

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
    // Box grids: cells partly above the ground whose own probe is inside the terrain, pointing
    // at the first valid probe above them (adaptive volumes count theirs in octree->borrowed).
    size_t borrowedCells = 0;
    // Terrain grids: probes lifted above height_offset to stand clear of the tracer's self-hit
    // distance (liftClearOfSelfHits); only on slopes far steeper than real terrain.
    size_t liftedForClearance = 0;
    float maxLift = 0.0f;  // metres, the largest of those lifts

    // Adaptive volumes: per probe, the key its bake seed derives from (the leaf's identity, so a
    // leaf gets the same bytes however the refinement reached it). Empty: seeds follow the index.
    std::vector<uint64_t> probeKeys;
    std::optional<AdaptiveOctree> octree;

    size_t validCount() const;
    // The occupancy as written to .shprobe: indices into the valid probes only, in placement
    // order (invalid probes are left out of the file), -1 where no probe.
    std::vector<int32_t> compactedOccupancy() const;
    // Bytes of the .shprobe this layout writes: 48 + 160 per valid probe + 4 per cell.
    uint64_t fileBytes() const;
};

// Exact lowest and highest point of the triangle surface (and its skirt) over the rectangle
// [x0, x1] × [z0, z1]: a piecewise-linear surface takes its extremes at the mesh vertices inside
// the rectangle and where the rectangle's edges cross grid lines and cell diagonals.
struct SurfaceRange {
    float lo = INFINITY, hi = -INFINITY;
};
SurfaceRange surfaceRange(const Heightfield& hf, double x0, double x1, double z0, double z1);

// The height at which a probe at p stands clear of the surface in every direction by twice
// the tracer's self-hit distance (HeightfieldTracer::minDistance), at least p.y. The tracer ignores
// hits nearer than that distance, so a probe closer to a face (5 m above a slope steeper than
// 5 m over that distance, as terrain.vertical_scale 100 makes) would send rays through it that
// then meet the terrain from below. The highest surface point within that distance
// horizontally is exact (surfaceRange), so the ball of that radius around the result holds no
// surface.
float liftClearOfSelfHits(const Heightfield& hf, const glm::vec3& p);

// A terrain-following probe: `offset` above the triangle surface at (x, z) the bake traces (a
// bilinear height can be metres below it), then lifted clear of self-hits (liftClearOfSelfHits);
// `lift` gets the metres of that lift. An offset of 0 or less leaves it on or in the surface,
// where it is not valid (y not above the surface).
glm::vec3 probeAboveSurface(const Heightfield& hf, float x, float z, double offset, float& lift);

// Where a volume's grid stands, resolved from its settings as the placement resolves them (one
// rule: the placement calls these too), without placing a probe: the viewport's bounds and handles.
// A terrain grid: the first probe's (x, z) and the spacing (0 on a one-probe axis is never used:
// auto-span gives 0 there, an explicit spacing is kept).
struct TerrainGridFrame {
    glm::vec2 first{0.0f}, spacing{0.0f};
};
TerrainGridFrame terrainGridFrame(const ProbeVolumeSettings& v, const Heightfield& hf);
// A box grid: its min corner and cubic cell edge.
struct BoxGridFrame {
    glm::vec3 origin{0.0f};
    float cell = 1.0f;
};
BoxGridFrame boxGridFrame(const ProbeVolumeSettings& v, const Heightfield& hf);
// An adaptive volume's box before the octree grows it to whole minimum cells: min corner, edges.
struct AdaptiveBox {
    glm::dvec3 origin{0.0}, size{0.0};
};
AdaptiveBox adaptiveBox(const ProbeVolumeSettings& v, const Heightfield& hf);

// Largest occupancy grid a volume may write (cells); bigger layouts are refused with a message.
inline constexpr uint64_t kMaxOccupancyCells = uint64_t(64) << 20;
// A terrain grid's occupancy cells per probe at most (a grid over a square footprint has a few).
inline constexpr uint64_t kMaxOccupancyCellsPerProbe = 1024;
// One cap per placement (docs/lighting.md, "Probe limits"): a terrain grid holds at most seed 000's
// 4096 probes; a box grid at most kMaxVolumeProbes cells, an adaptive volume at most that many
// valid probes (adaptive.max_probes may ask for fewer): 10 MiB of coefficients, the largest volume
// an engine is asked to allocate for.
inline constexpr int kMaxTerrainGridProbes = 4096;
inline constexpr int kMaxVolumeProbes = 65536;

// Throws PlacementError naming the volume setting, the value and the rule. Adaptive volumes get
// their geometric octree here (AdaptivePlacement.h refines it by error).
ProbeLayout placeProbes(const ProbeVolumeSettings& volume, const Heightfield& hf);

}  // namespace terralux
