#pragma once
// The terrain surface every part of Terralux agrees on: bake, viewport and exports.
//
// Engine space (docs/formats.md): Y up, X east, Z south, metres, origin at the centre of the DEM
// footprint at height 0. DEM sample (col, row) is mesh vertex (col, row); row 0 is the northern
// edge, so it lies at the most negative Z. Each cell between four vertices is split into two
// triangles along one fixed diagonal, from vertex (c, r) to (c + 1, r + 1):
//   triangle A = (c, r), (c, r + 1), (c + 1, r + 1)   covers fx <= fz
//   triangle B = (c, r), (c + 1, r + 1), (c + 1, r)   covers fx >  fz
// where fx, fz in [0, 1] are the position inside the cell along +X and +Z.

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

namespace terralux {

// Where the local origin sits on the Earth, kept in double precision (UTM-sized coordinates
// do not fit a float).
struct GeoOrigin {
    double easting = 0.0;   // metres, in crsWkt, of the footprint centre
    double northing = 0.0;  // metres
    double height = 0.0;    // metres; engine y = elevation - height
    std::string crsWkt;     // empty: the DEM carried no CRS
    std::string crsName;    // short human-readable name, e.g. "WGS 84 / UTM zone 31N"
    int epsg = 0;           // 0 when unknown
    // The footprint centre on the WGS 84 ellipsoid, degrees (north, east positive), and the true
    // azimuth of grid north (-Z) there, clockwise: a direction's true azimuth minus this is its
    // azimuth in engine space. NaN / 0 when the DEM carried no CRS.
    double latitudeDeg = std::numeric_limits<double>::quiet_NaN();
    double longitudeDeg = std::numeric_limits<double>::quiet_NaN();
    double gridConvergenceDeg = 0.0;
    bool located() const { return std::isfinite(latitudeDeg) && std::isfinite(longitudeDeg); }
};

class Heightfield {
public:
    Heightfield() = default;
    // heights: row-major, width * depth samples, metres. Throws std::invalid_argument on bad
    // dimensions, non-positive cell sizes or non-finite heights.
    Heightfield(int width, int depth, double cellSizeX, double cellSizeZ,
                std::vector<float> heights);

    int width() const { return width_; }   // vertices along X (DEM columns)
    int depth() const { return depth_; }   // vertices along Z (DEM rows)
    double cellSizeX() const { return cellSizeX_; }
    double cellSizeZ() const { return cellSizeZ_; }
    const std::vector<float>& heights() const { return heights_; }
    float at(int col, int row) const { return heights_[size_t(row) * size_t(width_) + size_t(col)]; }

    // Engine-space coordinate of a vertex column / row, and back (fractional, unclamped). The
    // engine origin lies at column originCol(), row originRow(): the grid's centre for a whole
    // DEM, elsewhere for a window of one (window()), which keeps its region's engine space.
    float xOf(double col) const { return float((col - originCol_) * cellSizeX_); }
    float zOf(double row) const { return float((row - originRow_) * cellSizeZ_); }
    double colOf(double x) const { return x / cellSizeX_ + originCol_; }
    double rowOf(double z) const { return z / cellSizeZ_ + originRow_; }
    double originCol() const { return originCol_; }
    double originRow() const { return originRow_; }

    // Columns [col0, col0 + width) and rows [row0, row0 + depth) of this grid, in this grid's
    // engine space (a vertex keeps its position to the bit), with their nodata marks and geo.
    // Throws std::invalid_argument when the window is empty or leaves the grid.
    Heightfield window(int col0, int row0, int width, int depth) const;
    // Places this grid as the window at (col0, row0) of a wholeWidth x wholeDepth grid centred on
    // the engine origin: what window() would have cut from it (a tile read alone from its DEM).
    void placeInGrid(int wholeWidth, int wholeDepth, int col0, int row0) {
        originCol_ = 0.5 * (wholeWidth - 1) - col0;
        originRow_ = 0.5 * (wholeDepth - 1) - row0;
        serial_ = nextSerial();
    }
    glm::vec3 vertex(int col, int row) const { return {xOf(col), at(col, row), zOf(row)}; }

    // Footprint in engine space (the vertex grid's extent).
    float minX() const { return xOf(0); }
    float maxX() const { return xOf(width_ - 1); }
    float minZ() const { return zOf(0); }
    float maxZ() const { return zOf(depth_ - 1); }
    float minHeight() const { return minHeight_; }
    // The mean of the samples (summed in double, in order), kept from construction: a 16 384²
    // grid's takes a quarter of a second to sum, which the camera and the docks asked for on
    // every refresh.
    float meanHeight() const { return meanHeight_; }
    float maxHeight() const { return maxHeight_; }
    // The lowest and highest sample in columns [col0, col1] and rows [row0, row1] (inclusive,
    // inside the grid, col0 <= col1, row0 <= row1). Whole blocks of kRangeBlock² samples are read
    // from their ranges, kept from construction, so a placement's cells of a 16 384² grid do not
    // read its 268 M samples one by one on every edit.
    std::pair<float, float> sampleRange(int col0, int col1, int row0, int row1) const;
    static constexpr int kRangeBlock = 16;
    bool contains(float x, float z) const {
        return x >= minX() && x <= maxX() && z >= minZ() && z <= maxZ();
    }

    // Height of the triangle surface at (x, z); outside the footprint the surface continues
    // at the nearest border point (the skirt of docs/lighting.md).
    float surfaceHeight(float x, float z) const;
    // Unit geometric normal of the triangle under (x, z) (the skirt is treated as level).
    glm::vec3 surfaceNormal(float x, float z) const;
    // Smooth per-vertex normal (central differences), what the mesh export and viewport shade.
    glm::vec3 vertexNormal(int col, int row) const;

    // Cells that were nodata in the source and were filled; empty when the source had none.
    const std::vector<uint8_t>& nodataMask() const { return nodataMask_; }
    void setNodataMask(std::vector<uint8_t> mask);
    size_t nodataCount() const { return nodataCount_; }

    // Names what this grid holds: its samples, cell sizes, placement in engine space and nodata
    // marks. A copy keeps it; building a grid, or changing its placement or marks, takes a new
    // one. What is derived from the grid alone (the water's auto level, a placement shown in a
    // dock) may be kept under it instead of computed again on every edit of the project.
    uint64_t serial() const { return serial_.value; }

    GeoOrigin geo;

private:
    static uint64_t nextSerial();
    // 0: the empty grid. A grid moved from keeps no samples, so it keeps no serial either.
    struct Serial {
        uint64_t value = 0;
        Serial() = default;
        Serial(uint64_t v) : value(v) {}
        Serial(const Serial&) = default;
        Serial& operator=(const Serial&) = default;
        Serial(Serial&& o) noexcept : value(std::exchange(o.value, 0)) {}
        Serial& operator=(Serial&& o) noexcept {
            value = std::exchange(o.value, 0);
            return *this;
        }
    };
    Serial serial_;
    int width_ = 0;
    int depth_ = 0;
    double cellSizeX_ = 1.0;
    double cellSizeZ_ = 1.0;
    double originCol_ = 0.0, originRow_ = 0.0;
    std::vector<float> heights_;
    std::vector<uint8_t> nodataMask_;
    float minHeight_ = 0.0f;
    float maxHeight_ = 0.0f;
    float meanHeight_ = 0.0f;
    // Per block of kRangeBlock² samples (the last row and column of blocks may be cut short),
    // row-major, blocksX_ a row: its lowest and highest sample.
    int blocksX_ = 0;
    std::vector<float> blockMin_, blockMax_;
    size_t nodataCount_ = 0;
};

}  // namespace terralux
