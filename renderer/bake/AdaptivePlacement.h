#pragma once
// Adaptive octree placement of SH probes over a terrain (seed 001's adaptive octree, written as
// docs/formats.md's .shprobe grid at the minimum cell size), the surface quadtree (its 2-D
// counterpart over the terrain-following layer), their error-driven refinement, and the
// interpolation model that the refinement and the reported interpolation error share.
//
// Surface placement. Squares from max_cell_size down to min_cell_size tile the terrain footprint
// (whole minimum cells; a square sticking out splits); each leaf holds one probe height_offset
// above the triangle surface over its centre, placed as a terrain grid places its probes. The
// .shprobe grid spans the footprint in minimum cells from the lowest ground to above the highest
// probe; a column's cells with any part above the terrain name its leaf's probe. Refinement tests
// a leaf's 4 quadrant centres (at height_offset above the ground there) as the octree tests its
// 8 octants, and splits it above the tolerance.
//
// Geometry. The box (auto: the terrain footprint from the lowest terrain point up to the highest
// + height_range) is made of whole minimum cells and tiled by root cells of max_cell_size. A cell
//   - is dropped when it lies wholly inside the terrain (its top at or below the lowest surface
//     point over its footprint): its grid cells hold -1;
//   - splits when it is larger than the minimum and sticks out of the box, or has its centre
//     inside the terrain, or is larger than surface_cell_size (default: the minimum) and reaches
//     into the surface band (its bottom below the highest surface point over its footprint plus
//     surface_band);
//   - otherwise is a leaf with one probe at its centre. A minimum-size leaf whose centre is inside
//     the terrain, or above it by less than 2 % of the cell, moves its probe up to 2 % of the
//     cell above the surface when that move is at most max_move_share of the cell; otherwise it
//     keeps no probe and its cell, partly above the terrain, points at the first probe above it
//     in its column (a cell with nothing above holds -1).
// Surface ranges over a footprint are exact for the triangle surface (Heightfield.h): a
// piecewise-linear surface takes its extremes over a rectangle at the mesh vertices inside it and
// where the rectangle's edges cross grid lines and cell diagonals.
//
// Interpolation model ("interpolated from its neighbours", docs/lighting.md's interpolation error).
// An engine reads the .shprobe occupancy grid. Filtered like a 3D texture, a point p gets the
// trilinear blend of the probes named by the 8 grid cells whose centres surround p; cells
// holding -1 (terrain, outside) are left out and the weights renormalised. Inside a leaf two or
// more cells wide this is the leaf's own probe, which is also what seed 001's nearest-cell
// lookup returns; near a leaf's faces it blends towards the neighbours.
//
// Error-driven refinement (tolerance set). Each leaf larger than the minimum bakes probes at the
// centres of its 8 octants, where its children's probes would go. The model gives the leaf's own
// probe there, so the leaf's error is the largest relative irradiance error (docs/lighting.md probe
// error: RMS over 256 normals) of its probe against those 8 bakes (octants whose centre is in the
// terrain left out: no point above the surface is lit as they are); above the tolerance it splits
// and its children keep the octant bakes (same position, same seed). Rounds go one level down at
// a time; in each round the worst leaves split first, and a budget (max_probes, max_bytes) stops
// the refinement at the first split that no longer fits.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/ext/vector_double3.hpp>

#include "bake/DiffuseBake.h"
#include "bake/ProbePlacement.h"

namespace terralux {

// The minimum cell an adaptive volume gets when min_cell_size is unset: the DEM cell, but no
// finer than 1/kAutoMinCellsAlongBox of the box's longer horizontal side. A 90 m DEM of 110 km
// at its own cell needs 5.6 M probes and 1 GB (or exceeds kMaxOccupancyCells); 128 cells along
// the box keep every DEM in the tens of thousands of probes, a few seconds of bake.
inline constexpr double kAutoMinCellsAlongBox = 128.0;
double autoMinCellSize(const Heightfield& hf, const glm::dvec3& boxSize);

// A surface volume's squares when adaptive.min_cell_size / max_cell_size are unset. The smallest
// is half the DEM cell (the light a few metres above rough ground changes within one cell: on the
// Rainier crop probes at every cell leave a 13 % p95, at half cells 9 %), coarsened until the
// occupancy grid over the footprint and its relief holds at most kAutoSurfaceCells (16 MiB; on a
// 110 km SRTM tile that is about 190 m). The largest is the largest min x 2^k at most 1/8 of the
// footprint's longer side, so the unrefined quadtree is about seed 000's 8 x 8 terrain grid.
inline constexpr double kAutoSurfaceCells = double(4 << 20);
double autoSurfaceMinCell(const Heightfield& hf, double heightOffset);
double autoSurfaceMaxCell(const Heightfield& hf, double minCell);

// Geometric adaptive placement (no refinement). Throws PlacementError for settings that only
// the terrain can check (auto sizes), an occupancy grid over kMaxOccupancyCells, or a budget the
// surface band alone already exceeds.
ProbeLayout placeAdaptive(const ProbeVolumeSettings& volume, const Heightfield& hf);

// The seed key of a leaf: a hash of its level and corner, independent of any ordering.
uint64_t octreeLeafKey(const OctreeLeaf& leaf);

// Bakes probes at `positions`, probe i seeded from keys[i] only (bakeProbesSeeded). The result's
// vectors are aligned with `positions`.
using ProbeBaker = std::function<ProbeBake(const std::vector<glm::vec3>& positions,
                                           const std::vector<uint64_t>& keys)>;

// The baker of a real bake: probe i seeded from seed ^ keys[i], with the irradiance cache
// (bakeProbesSeeded) or, for `reference`, the path-traced reference (referenceProbesSeeded).
// `lighting` and `cache` must outlive the baker.
ProbeBaker seededBaker(const BakeLighting& lighting, const IrradianceCache* cache, int bounces,
                       const ProbeRays& rays, uint64_t seed, const BakeControl& control, bool reference = false);

// `baker` whose probes get the deringing window when `dering` (bake.deringing), as the probes a
// bake writes do: a truth baked with it differs from those probes by interpolation alone. `rays`
// (optional) accumulates the rays it traced.
ProbeBaker deringedBaker(ProbeBaker baker, bool dering, uint64_t* rays = nullptr);

struct AdaptiveRefinement {
    double tolerance = 0.0;
    int rounds = 0;
    size_t leavesTested = 0;       // leaves larger than the minimum whose octants were baked
    size_t leavesSplit = 0;
    size_t octantProbes = 0;       // probes baked at octant centres
    size_t octantProbesKept = 0;   // of those, how many became probes of split leaves
    double worstKeptError = 0.0;   // largest error of a tested leaf that was not split
    bool budgetReached = false;
    size_t leavesOverTolerance = 0;  // leaves the budget left unsplit above the tolerance
};

struct AdaptiveBake {
    ProbeLayout layout;
    ProbeBake bake;  // aligned with layout.positions; zero for positions without a probe
    std::optional<AdaptiveRefinement> refinement;  // set when the volume has a tolerance
};

// Places the octree, bakes every probe with `baker` and, with a tolerance, refines by error.
// `onRound` (optional) hears the round number and the leaves it tests. The baker's exceptions
// (BakeCancelled) pass through.
AdaptiveBake bakeAdaptive(const ProbeVolumeSettings& volume, const Heightfield& hf,
                          const ProbeBaker& baker,
                          const std::function<void(int round, size_t leaves)>& onRound = {});

// The interpolation model above, over any layout's occupancy grid (terrain and box grids too);
// sh[i] belongs to layout.positions[i]. false: no occupied cell around p (the engine falls back).
bool interpolateProbes(const ProbeLayout& layout, const std::vector<sh::ShRgb>& sh,
                       const glm::vec3& p, sh::ShRgb& out);

struct InterpolationError {
    size_t points = 0;     // sampled points that had probes around them
    size_t uncovered = 0;  // sampled points above the terrain with none (left out of the stats)
    double mean = 0, p95 = 0, max = 0;
    std::optional<double> withinTolerance;  // share of points with error <= tolerance
    std::vector<glm::vec3> positions;       // the points counted, with their errors
    std::vector<float> errors;
};

// docs/lighting.md interpolation error: at `count` points drawn uniformly (deterministically from
// `seed`) from the part of the layout's grid box above the terrain (a surface volume's: from the
// ground up to twice its height_offset), the relative irradiance error
// of the interpolated probes against a probe baked at the point with `baker`.
InterpolationError measureInterpolationError(const ProbeLayout& layout,
                                             const std::vector<sh::ShRgb>& sh,
                                             const Heightfield& hf, const ProbeBaker& baker,
                                             int count, uint64_t seed,
                                             std::optional<double> tolerance);

}  // namespace terralux
