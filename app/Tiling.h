#pragma once
// A region cut into tiles for a farm (docs/farm.md): each tile bakes its own share of the terrain
// as a complete bake, seeing the terrain within a halo around it, in the region's engine space,
// so a merge lists the tiles' grids side by side with no transform.

#include <array>
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "DemImport.h"
#include "terrain/Heightfield.h"

namespace terralux {

// The folder under a region's output folder that holds one folder per tile.
inline constexpr const char* kTilesFolder = "tiles";

// One tile of an nx × nz cut: column ix (west to east), row iz (north to south).
struct TileSpec {
    int nx = 1, nz = 1;
    int ix = 0, iz = 0;
    std::optional<double> haloMetres;  // unset: haloFor() derives it from the relief
    // How much of the halo is read at the DEM's resolution; unset: nearHaloFor() derives it.
    std::optional<double> nearHaloMetres;
    int index() const { return iz * nx + ix; }
    int count() const { return nx * nz; }
};

// "--tiles NX,NZ" and "--tile I/N" (I in [0, N), row-major: I = iz·NX + ix) or "--tile IX,IZ".
// Throws std::invalid_argument with a one-line message naming the option, the value and the rule.
TileSpec parseTiles(const std::string& tiles, const std::string& tile, const std::optional<double>& haloMetres);

// The share of an upward receiver's irradiance that terrain beyond the halo may change: the
// halo's rule (haloFor).
inline constexpr double kHaloShare = 0.01;

// How far beyond a tile the terrain can still change its light by more than kHaloShare: terrain
// at a distance d beyond the tile, at most `relief` above the lowest ground, stands at most
// atan(relief / d) above a receiver's horizon; the cosine-weighted share of the hemisphere below
// that elevation is sin²(atan(relief / d)), which is kHaloShare at d = relief·√((1 − s) / s)
// (≈ 9.95 × the relief). Such terrain can shade the sun only below atan(relief / d) (5.7°).
struct Halo {
    double metres = 0.0;
    bool derived = true;
    double relief = 0.0;           // metres, highest minus lowest ground of the region
    double sunBelowDeg = 0.0;      // terrain beyond the halo can shade only a sun lower than this
};
Halo haloFor(const DemGrid& region, const std::optional<double>& metres);

// How much of the halo a tile reads at the DEM's resolution; beyond it the halo is traced on the
// region's overview (RegionSummary), whose cells are `overviewCell` metres (the larger side). A
// height error e at distance d moves a receiver's horizon by at most e / d radians, and the
// cosine-weighted share of the hemisphere below elevation θ, sin²θ, moves by at most that (its
// derivative, sin 2θ, is at most 1). The overview's area-averaged surface lies within about a
// cell of the DEM's where the slopes across a cell are under 45°, so from d = overviewCell /
// kHaloShare (a hundred overview cells) on, it changes a receiver's light by at most kHaloShare.
// Never wider than the halo; `metres` overrides the rule.
double nearHaloFor(const Halo& halo, double overviewCell, const std::optional<double>& metres);

// The grid of a heightfield already in memory, as demGrid describes a DEM's.
inline DemGrid gridOf(const Heightfield& hf) {
    return {hf.width(), hf.depth(), hf.cellSizeX(), hf.cellSizeZ(), hf.minHeight(), hf.maxHeight(), false};
}

// A tile's vertex windows in the region's grid. The core: columns [col0, col0 + cols); tiles
// share their border column and row, so their meshes and probe grids meet without a gap or an
// overlap. The traced window: the core grown by the near halo, clipped to the region, read at the
// DEM's resolution. The halo window: the core grown by the whole halo; where it is wider than the
// traced window (`far`), the ring between them is traced on the region's overview.
struct TileWindow {
    int col0 = 0, row0 = 0, cols = 0, rows = 0;
    int tracedCol0 = 0, tracedRow0 = 0, tracedCols = 0, tracedRows = 0;
    int haloCol0 = 0, haloRow0 = 0, haloCols = 0, haloRows = 0;
    int regionCols = 0, regionRows = 0;  // the region's vertex grid
    Halo halo;
    double nearMetres = 0.0;
    bool far = false;
};
// `overviewCell`: the region overview's cell (the larger side), for nearHaloFor; 0 reads the whole
// halo at the DEM's resolution. Throws std::invalid_argument when the region has fewer than 2
// cells a tile along an axis.
TileWindow tileWindow(const DemGrid& region, const TileSpec& tile, double overviewCell = 0.0);

// The engine-space x of the region grid's column `col` and z of its row `row`, as
// Heightfield::xOf and zOf place a whole DEM's vertices.
inline double regionX(const DemGrid& region, double col) { return (col - 0.5 * (region.width - 1)) * region.cellX; }
inline double regionZ(const DemGrid& region, double row) { return (row - 0.5 * (region.depth - 1)) * region.cellZ; }

// The region overview's vertices over a tile's halo window, rounded outward (at least 2 a side):
// the overview and the region share the engine space, so the window needs no transform.
GridWindow overviewWindow(const TileWindow& w, const DemGrid& region, const Heightfield& overview);

// "tile_003_001": sorts as the seed's merge lists grids (by file name), west to east in a row.
std::string tileName(const TileSpec& tile);

// What a tile's bake reads and traces, beyond its settings: 2 since the halo past the near halo
// is traced on the region's overview, 3 since a tile leaves the reflection probes of a border it
// shares to its neighbour. A tile baked under another contract is baked again, and a merge
// refuses to mix them.
inline constexpr int kTileContract = 3;

// What a tile's bake_report.json records under "tile": the cut, the windows, the halo rules and
// the contract.
nlohmann::json tileReport(const TileSpec& tile, const TileWindow& w, const DemGrid& region);

}  // namespace terralux

namespace terralux {
struct SceneDescription;
struct ReflectionProbeSettings;
// The scene a tile bakes: each terrain and box volume's grid_dims, and the reflection grid's,
// scaled to the tile's share of the region's cells (a terrain grid over auto-span keeps the
// region's spacing when the tile's cells are a whole number of it), so the tiles together place
// what the region would. Throws ProjectError for what cannot be cut: an explicit origin, or an
// adaptive volume's explicit size (each tile places over its own footprint).
void scaleSceneToTile(SceneDescription& scene, const TileWindow& w);
// A tile's reflection grid as it places it: scaleSceneToTile's share, its end probes on the
// tile's edges, less the column on its east edge and the row on its south edge where another tile
// shares that border (that tile holds them), so the merged sets hold every probe once. The
// spacing and origin become explicit (those of the grid before the cut); an axis of one probe,
// centred on the tile, keeps it.
ReflectionProbeSettings tileReflectionGrid(const ReflectionProbeSettings& share, const TileWindow& w,
                                           const Heightfield& tile);
// The terrain grid_dims of the region whose tile share (scaleSceneToTile's rule) is `tileDims`
// [x, z]: what a suggestion measured on one tile asks of the project.
std::array<int, 2> regionTerrainGridDims(const std::array<int, 2>& tileDims, const TileWindow& w);
// The probes of a region's terrain grid of `probes` that fall to the tile, rounded down, with a
// margin for the rounding of each axis: a tile's grid within it names a region grid within `probes`.
int tileShareOfProbes(int probes, const TileWindow& w);
}  // namespace terralux

namespace terralux {
struct Project;
// What every tile of a region needs of the whole region: its grid (demGrid) and an overview of
// at most kRegionOverview samples a side (area-averaged) on which the exported lighting resolves.
// Each is a pass over the whole raster, so the first tile computes them and leaves them in
// `cacheDir` (region.json, region.f32), keyed by the DEM's identity (path, size, modification
// time) and the import settings; the other tiles read them. Written atomically: tiles that
// compute them at once write the same bytes.
inline constexpr int kRegionOverview = 1024;
struct RegionSummary {
    DemGrid grid;
    Heightfield overview;
    bool cached = false;  // read from cacheDir
};
// `write` false (a dry run): computed when absent but not left in cacheDir.
RegionSummary regionSummary(const Project& project, const std::filesystem::path& cacheDir, bool write = true);
}  // namespace terralux
