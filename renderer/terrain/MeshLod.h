#pragma once
// The terrain mesh's level of detail. The drawn grid (the DEM's vertices, or every k-th under the
// renderer's vertex budget) is cut into square patches; each frame every patch draws every
// 2^l-th of its vertices along each axis (its last row and column always), choosing the coarsest
// level whose geometric error, seen from the camera at the patch's nearest point, covers at most
// a pixel. A shared edge is drawn with the vertices of the coarser of its two patches, and the
// finer patch zips its ring of cells to them, so the mesh has no cracks whatever the levels.
// Every vertex is a vertex of the drawn grid, so per-vertex data (probe light, sun visibility)
// serves every level.

#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

namespace terralux::lod {

// The vertices a level keeps along an axis of n: 0, step, 2 step, ... and n - 1.
std::vector<uint32_t> kept(uint32_t n, uint32_t step);

// Appends the triangles of the grid through columns kc and rows kr of an nc-wide vertex grid
// (vertex (c, r) is index r * nc + c): two per cell, split along (c, r)-(c+1, r+1), counter-
// clockwise seen from above (y up, rows along +z).
void appendTriangles(std::vector<uint32_t>& indices, uint32_t nc, const std::vector<uint32_t>& kc,
                     const std::vector<uint32_t>& kr);

// The largest |h - s| over the vertices of the nc-wide height grid `heights` (row-major) from
// column kc.front() to kc.back() and row kr.front() to kr.back(), where s is the surface of the
// grid through columns kc and rows kr at that vertex: two triangles per cell, split as
// appendTriangles splits them, linear across each, in the world coordinates colX and rowZ of
// the grid's columns and rows where given (a decimated grid's last step is shorter), else in grid
// steps.
double gridError(std::span<const float> heights, uint32_t nc, const std::vector<uint32_t>& kc,
                 const std::vector<uint32_t>& kr, std::span<const float> colX = {}, std::span<const float> rowZ = {});

// The distance from p to the box [lo, hi] (0 inside it).
double distanceToBox(const glm::vec3& p, const glm::vec3& lo, const glm::vec3& hi);

// Pixels a geometric error of `metres` covers at most, seen `distance` metres away through a
// perspective camera with a vertical field of view fovY (radians) over heightPixels rows: the
// angle an offset subtends is at most metres / distance, and a pixel subtends
// 2 tan(fovY / 2) / heightPixels at the centre of the image (less at its edges). At distance 0,
// infinity unless the error is 0.
double screenPixels(double metres, double distance, double fovY, double heightPixels);

// The drawn grid cut into patches of about `patchCells` cells a side (the last ones take the
// remainder), with each patch's bounds and the error of each of its levels.
struct Patches {
    uint32_t nc = 0, nr = 0;               // the drawn grid's vertices along each axis
    std::vector<uint32_t> cols, rows;      // patch boundaries: patch (i, j) spans columns
                                           // cols[i]..cols[i+1] and rows rows[j]..rows[j+1]
    uint32_t levels = 1;                   // levels a patch may have (the largest count)
    std::vector<uint8_t> coarsest;         // per patch: its last level (2 cells a side at least)
    std::vector<double> error;             // per patch, per level (patch * levels + l): metres
    std::vector<glm::vec3> lo, hi;         // per patch: its bounds in the world
    std::vector<float> x, z;               // the drawn grid's columns' and rows' world coordinates
    uint32_t patchesX() const { return uint32_t(cols.size()) - 1; }
    uint32_t patchesZ() const { return uint32_t(rows.size()) - 1; }
    uint32_t count() const { return patchesX() * patchesZ(); }
};

// `heights` is the drawn grid (nc x nr, row-major), colX and rowZ its columns' and rows' world
// coordinates. A level's error is what it leaves out of the drawn grid (0 at level 0).
Patches buildPatches(std::span<const float> heights, uint32_t nc, uint32_t nr, std::span<const float> colX,
                     std::span<const float> rowZ, uint32_t patchCells);

// Each patch's level: the coarsest whose error, and every finer level's, covers at most
// maxPixels seen from `eye` at the patch's nearest point.
std::vector<uint8_t> chooseLevels(const Patches& p, const glm::vec3& eye, double fovY, double heightPixels,
                                  double maxPixels);

// The step of patch `patch`'s level: 2^level.
inline uint32_t stepOf(uint8_t level) { return 1u << level; }

// Appends the triangles of every patch at its level, zipped along edges shared with a coarser
// patch (as appendTriangles winds and, where no edge is zipped, splits them), and returns the
// mesh's border segments at the border patches' steps: pairs of vertex indices, in order along
// the border, for the skirt.
// Patches with detail[k] >= 0 (detail patches, below) give neither triangles nor border segments.
void appendPatchTriangles(std::vector<uint32_t>& indices, const Patches& p, std::span<const uint8_t> levels,
                          std::vector<uint32_t>* borderSegments = nullptr, std::span<const int8_t> detail = {});

// Source resolution under a decimated drawn grid: the drawn grid's column c is the source grid's
// column col[c] (its row r, row[r]). A patch whose drawn vertices leave too much of the source
// out may be drawn from the source grid instead, a detail patch at detail level d: every 2^d-th
// source vertex of its span along each axis (its last row and column always). It holds its own
// vertices (detailVertices); those it shares with the drawn grid have the same positions, so it
// meets its drawn neighbours without cracks.
struct SourceGrid {
    uint32_t nc = 0, nr = 0;         // the source grid's vertices along each axis
    std::vector<uint32_t> col, row;  // per drawn column / row: its source column / row
    std::vector<float> x, z;         // the source columns' and rows' world coordinates
};
// Patch k's span of the source grid: columns c0..c1, rows r0..r1.
struct SourceSpan {
    uint32_t c0 = 0, c1 = 0, r0 = 0, r1 = 0;
    uint32_t nc() const { return c1 - c0 + 1; }
    uint32_t nr() const { return r1 - r0 + 1; }
    size_t vertices() const { return size_t(nc()) * nr(); }
};
SourceSpan sourceSpan(const Patches& p, const SourceGrid& g, uint32_t k);

// The vertices detail patch k at level d holds, as its span's own indices (r - r0) * nc() +
// (c - c0), ascending: its level's grid and every source vertex of its four edges, so whatever
// its sides, each edge's vertices are among them.
// (A patch spans two cells a side at least.) detailVertexCount is their number, without listing them.
std::vector<uint32_t> detailVertices(const Patches& p, const SourceGrid& g, uint32_t k, uint8_t d);
size_t detailVertexCount(const Patches& p, const SourceGrid& g, uint32_t k, uint8_t d);

// Appends detail patch k's triangles at its level detail[k], vertex detailVertices()[m] being
// index base + m. Each edge is drawn at the coarser of the two sides: with a detail neighbour,
// the coarser detail step; with a drawn neighbour, the drawn vertices that neighbour's level
// keeps on it (as appendPatchTriangles draws it); at the border, its own step (appendDetailSkirt
// closes it). The ring along an edge coarser than the patch is zipped.
void appendDetailPatch(std::vector<uint32_t>& indices, const Patches& p, const SourceGrid& g,
                       std::span<const uint8_t> levels, std::span<const int8_t> detail, uint32_t k, uint32_t base);

// The skirt under a detail patch's border edges: after the vertices detailVertices lists, the
// patch holds a twin pushed out across the border for each vertex of each border edge at its
// step, edge by edge in the order north (row r0), south, west (column c0), east, each along the
// edge. `detailSkirtTwins` lists them (the source vertex and the outward direction in (x, z));
// appendDetailSkirt appends each segment of those edges and its twins as two triangles, wound
// as appendSkirt winds them. (The DEM's corners are drawn vertices: the drawn skirt's corner
// squares serve.)
struct DetailTwin {
    uint32_t c, r;
    int dx, dz;
};
std::vector<DetailTwin> detailSkirtTwins(const Patches& p, const SourceGrid& g, uint32_t k, uint8_t d);
void appendDetailSkirt(std::vector<uint32_t>& indices, const Patches& p, const SourceGrid& g,
                       std::span<const int8_t> detail, uint32_t k, uint32_t base);

// The largest |h - s| over the source vertices of detail patch k's span, s the surface its
// triangles (appendDetailPatch) draw there; `heights` is the source grid, row-major.
double detailSurfaceError(const Patches& p, const SourceGrid& g, std::span<const uint8_t> levels,
                          std::span<const int8_t> detail, uint32_t k, std::span<const float> heights);
// What detail level d of patch k leaves out of the source grid, without zipping.
double detailLevelError(const Patches& p, const SourceGrid& g, uint32_t k, uint8_t d, std::span<const float> heights);

// Spending a vertex budget over the patches that want detail. Each candidate has a sequence of
// states, coarsest first (state 0: drawn from the drawn grid, at no cost), each with its error on
// screen (pixels) and its vertices (rising along the sequence), and a target state (within the
// pixel). Within the budget every candidate takes its target. Past it the largest error is made as
// small as the budget allows: the candidate furthest off moves to its cheapest finer state that is
// nearer, until every candidate is within maxPixels or has no such move that fits (a candidate
// whose move does not fit keeps its state, and the budget left brings the others nearer).
// (Optimal for the largest error: the largest never grows, so every state passed by was at
// least the largest when the first move did not fit, and a smaller largest would need more than
// each candidate holds and more than the budget.) Returns each candidate's state.
struct DetailCandidate {
    std::vector<double> pixels;
    std::vector<size_t> vertices;
    size_t target = 0;
};
std::vector<size_t> allocateDetail(std::span<const DetailCandidate> candidates, size_t budget, double maxPixels);

// Per patch, the largest |h - s| over its vertices of the drawn grid, s the surface its triangles
// at `levels` draw there (appendPatchTriangles's): its level's error where no edge is zipped, and
// where one is, measured under every triangle of the patch, so a ring zipped to a coarser
// neighbour's edge counts what it leaves out. Vertex (c, r)'s height is
// heights[stride * (r * nc + c)].
// `cache`, kept between calls over the same patches, keeps each patch's error until its level or
// a neighbour's changes.
struct SurfaceErrorCache {
    std::vector<uint64_t> key;  // per patch: its level and its four neighbours'
    std::vector<double> error;
};
std::vector<double> surfaceErrors(const Patches& p, std::span<const uint8_t> levels, std::span<const float> heights,
                                  size_t stride = 1, SurfaceErrorCache* cache = nullptr);

// A ring zipped to a coarser neighbour's edge is a surface neither patch's level has, and can
// stray further than either: each patch whose ring strays past its own level's error and past
// maxPixels seen from `eye` has its coarser neighbours drawn a level finer, until none does.
// Returns the final levels' surfaceErrors, so every patch's surface is within maxPixels (or
// within what its own level leaves out, where chooseLevels kept that finer than asked).
std::vector<double> settleRings(const Patches& p, std::vector<uint8_t>& levels, std::span<const float> heights,
                                size_t stride, const glm::vec3& eye, double fovY, double heightPixels, double maxPixels,
                                SurfaceErrorCache* cache = nullptr);

// The skirt's vertices (the renderer's terrain.skirt): for each border vertex of the drawn grid
// its twin pushed out across that border (a corner vertex has one per border), and the four
// corner squares' triangles.
struct SkirtVertices {
    uint32_t nc = 0, nr = 0;
    std::vector<uint32_t> north, south;  // per column: twins of row 0 and row nr - 1
    std::vector<uint32_t> west, east;    // per row: twins of column 0 and column nc - 1
    std::vector<uint32_t> corners;       // triangles
};

// Appends the skirt for `segments` (pairs of border vertices from appendPatchTriangles): each
// segment and its twins as two triangles, then the corner squares.
void appendSkirt(std::vector<uint32_t>& indices, const SkirtVertices& k, const std::vector<uint32_t>& segments);

}  // namespace terralux::lod
