#pragma once
// DEM import: any raster GDAL opens, band 1, into an engine-space Heightfield.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "Membrane.h"

#include "terrain/Heightfield.h"

namespace terralux {

// A user-facing failure: one line that names the file, the problem and, where it helps, the rule.
class DemError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Vertices [col0, col0 + cols) x [row0, row0 + rows) of the grid an import makes.
struct GridWindow {
    int col0 = 0, row0 = 0, cols = 0, rows = 0;
};

struct DemImportOptions {
    // 0 = keep the source resolution; otherwise the longer side is reduced to at most this many
    // samples by area averaging.
    int maxResolution = 0;
    // Rasters with more cells than this (after maxResolution) are refused before any pixel is
    // read: 4 bytes per cell for heights plus the working copies GDAL needs.
    double maxCells = 256.0 * 1024 * 1024;
    double verticalScale = 1.0;
    // Set: the import returns only this window of the grid it would make, in that grid's engine
    // space (as Heightfield::window cuts it), with the whole grid's geo origin, read alone
    // (DemSourceInfo::windowRead): a source whose cells are the grid's (projected, north up, not
    // reduced) only there; one that is reprojected or reduced through a virtual warp or
    // resampling of the whole grid, which computes the window's cells and no others (its
    // coverage, a byte a cell of the whole grid, places the trim). Heights memory follows the
    // window, not the raster. Nodata holes are filled from the window's own cells.
    std::optional<GridWindow> window;
};

// What the source was, before reprojection; what `terralux --info` prints.
struct DemSourceInfo {
    std::string path;
    std::string driver;          // GDAL short name, e.g. "GTiff", "SRTMHGT", "AAIGrid"
    int sourceWidth = 0;
    int sourceHeight = 0;
    std::string sourceCrs;       // name, or empty
    int sourceEpsg = 0;
    bool geographic = false;     // source CRS was geographic (or Web Mercator) and was reprojected
    bool reprojected = false;
    bool resampled = false;      // maxResolution reduced the grid
    double sourcePixelX = 0.0;   // source units, as the geotransform says
    double sourcePixelY = 0.0;
    std::string sourcePixelUnit = "m";  // of sourcePixelX/Y: "deg" for a geographic CRS, else the
                                        // CRS's linear unit ("m", "ft", "US survey foot")
    std::vector<std::string> warnings;  // e.g. no CRS: cells taken as metres
    bool windowRead = false;            // DemImportOptions::window was read alone from the source
};

struct DemImportResult {
    Heightfield heightfield;
    DemSourceInfo source;
};

// How nodata holes are filled (docs/lighting.md, "Terrain").
enum class VoidFill {
    // GDALFillNodata: inverse distance weighting over a search in four directions, then 3x3
    // smoothing passes over the filled cells. Kept to measure the membrane against.
    Gdal,
    // The membrane (Laplace) surface over the holes, the valid cells around each hole fixed:
    // conjugate gradients with a multigrid preconditioner from the mean of the hole's rim
    // (Membrane.h). GDAL's search costs its holes' cells times the grid's side (40 s for the
    // 4 % nodata collars of a 4800^2 reprojected tile); the membrane's start does not matter.
    Membrane,
};
// What importDem uses: the better of the two in the measurements of README.md.
inline constexpr VoidFill kImportVoidFill = VoidFill::Membrane;

// Fills the cells where nodata[i] != 0 of a row-major w x h grid from the others; cells with
// nodata[i] == 0 are left unchanged. Every hole is filled if at least one cell is valid. Throws
// DemError when GDAL fails or memory runs out. Returns how the membrane solve went (nothing
// for VoidFill::Gdal).
MembraneReport fillVoids(std::vector<float>& heights, int w, int h, const std::vector<uint8_t>& nodata,
                         VoidFill method = kImportVoidFill);

// Reads `path` (a file, or any GDAL virtual path such as /vsizip/...). Throws DemError.
DemImportResult importDem(const std::string& path, const DemImportOptions& options = {});

// The grid importDem makes of `path`: its size, cell sizes and height range (after the vertical
// scale), from the header (and, reprojected, the coverage of the warp) and one streamed pass over
// the source's blocks (GDAL's exact minimum and maximum of its valid cells), never holding the
// raster. Reprojected or reduced, that range is the source's, which bounds the grid's (bilinear
// and averaged values, and filled holes, lie within the values around them). `streamed` is always
// true; kept for the region summary's file. Throws DemError as importDem does.
struct DemGrid {
    int width = 0, depth = 0;
    double cellX = 0.0, cellZ = 0.0;
    double minHeight = 0.0, maxHeight = 0.0;
    bool streamed = false;
};
DemGrid demGrid(const std::string& path, const DemImportOptions& options = {});
DemGrid demGridFromMemory(const std::string& name, const unsigned char* bytes, size_t size,
                          const DemImportOptions& options = {});

// Where a reprojected grid has source cells, row by row: each row's covered runs [first, last]
// of columns (inclusive, ascending). The import trims the grid to the largest window whose border
// is covered, and holds this, a few integers a row, rather than a byte a cell of the whole grid.
struct CoverageRuns {
    int width = 0;
    std::vector<std::vector<std::pair<int, int>>> rows;
    // Row y from its `width` cells (non-zero: covered).
    void addRow(int y, const uint8_t* cells);
    bool covers(int x, int y) const;
};

// The UTM zone EPSG code (WGS 84) for a geographic position: 326zz north, 327zz south.
int utmEpsgFor(double longitudeDeg, double latitudeDeg);

}  // namespace terralux

namespace terralux {
// Imports a raster held in memory (e.g. the sample compiled into the binary); `name` is the file
// name GDAL sees (its extension helps pick the driver) and the name messages use.
DemImportResult importDemFromMemory(const std::string& name, const unsigned char* bytes,
                                    size_t size, const DemImportOptions& options = {});
}  // namespace terralux
