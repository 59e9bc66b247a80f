#include "bake/ProbePlacement.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "bake/AdaptivePlacement.h"
#include "bake/HeightfieldTracer.h"

namespace terralux {

std::vector<int32_t> ProbeLayout::compactedOccupancy() const {
    std::vector<int32_t> compact(positions.size(), -1);
    int32_t next = 0;
    for (size_t i = 0; i < positions.size(); ++i)
        if (valid[i]) compact[i] = next++;
    std::vector<int32_t> out(cellProbe.size());
    for (size_t c = 0; c < cellProbe.size(); ++c)
        out[c] = cellProbe[c] < 0 ? -1 : compact[size_t(cellProbe[c])];
    return out;
}

size_t ProbeLayout::validCount() const {
    return size_t(std::count(valid.begin(), valid.end(), uint8_t(1)));
}

SurfaceRange surfaceRange(const Heightfield& hf, double x0, double x1, double z0, double z1) {
    const int w = hf.width(), d = hf.depth();
    auto gu = [&](double x) {
        return std::clamp(hf.colOf(x), 0.0, double(w - 1));
    };
    auto gv = [&](double z) {
        return std::clamp(hf.rowOf(z), 0.0, double(d - 1));
    };
    // Beyond the footprint the skirt repeats the border (Heightfield::surfaceHeight): clamp.
    const double u0 = gu(x0), u1 = gu(x1), v0 = gv(z0), v1 = gv(z1);
    auto heightAt = [&](double u, double v) { return hf.surfaceHeight(hf.xOf(u), hf.zOf(v)); };
    SurfaceRange r;
    auto add = [&](float h) {
        r.lo = std::min(r.lo, h);
        r.hi = std::max(r.hi, h);
    };
    if (const int c0 = int(std::ceil(u0)), c1 = int(std::floor(u1)), r0 = int(std::ceil(v0)),
        r1 = int(std::floor(v1));
        c0 <= c1 && r0 <= r1) {
        const auto [lo, hi] = hf.sampleRange(c0, c1, r0, r1);
        add(lo);
        add(hi);
    }
    // Along an edge of constant v: its ends, the grid lines u = col and the diagonals of the
    // cells it runs through (u - col = v - row, Heightfield.h).
    auto alongU = [&](double v) {
        add(heightAt(u0, v));
        add(heightAt(u1, v));
        for (int col = int(std::ceil(u0)); col <= int(std::floor(u1)); ++col) add(heightAt(col, v));
        const int row = std::min(int(v), std::max(d - 2, 0));
        const double f = v - row;
        for (int col = std::max(int(std::floor(u0)) - 1, 0); col <= int(std::floor(u1)); ++col)
            if (const double u = col + f; u > u0 && u < u1) add(heightAt(u, v));
    };
    auto alongV = [&](double u) {
        add(heightAt(u, v0));
        add(heightAt(u, v1));
        for (int row = int(std::ceil(v0)); row <= int(std::floor(v1)); ++row) add(heightAt(u, row));
        const int col = std::min(int(u), std::max(w - 2, 0));
        const double f = u - col;
        for (int row = std::max(int(std::floor(v0)) - 1, 0); row <= int(std::floor(v1)); ++row)
            if (const double v = row + f; v > v0 && v < v1) add(heightAt(u, v));
    };
    alongU(v0);
    alongU(v1);
    alongV(u0);
    alongV(u1);
    return r;
}

uint64_t ProbeLayout::fileBytes() const {
    return 48 + 160 * uint64_t(validCount()) + 4 * uint64_t(cellProbe.size());
}

namespace {

std::string num(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

// Terrain-following grid (seed 000): nx × nz probes at the height of the triangle surface the
// bake traces plus the offset (a bilinear height can be metres below that surface, so a
// positive offset could leave a probe inside the terrain). Auto-span puts the end probes on the footprint edges; a 1-wide axis is centred.
ProbeLayout placeTerrainGrid(const ProbeVolumeSettings& v, const Heightfield& hf) {
    const std::string where = "probe_volumes '" + v.name + "'";
    ProbeLayout L;
    const int nx = v.gridDims[0], nz = v.gridDims[2];
    L.probeDims = {nx, 1, nz};
    const float spanX = hf.maxX() - hf.minX(), spanZ = hf.maxZ() - hf.minZ();
    const TerrainGridFrame frame = terrainGridFrame(v, hf);
    const glm::vec3 spacing(frame.spacing.x, 0.0f, frame.spacing.y);
    const glm::vec3 first(frame.first.x, 0.0f, frame.first.y);
    L.spacing = spacing;
    for (int k = 0; k < nz; ++k)
        for (int i = 0; i < nx; ++i) {
            const float x = first.x + spacing.x * float(i), z = first.z + spacing.z * float(k);
            float lift = 0.0f;
            const glm::vec3 p = probeAboveSurface(hf, x, z, v.heightOffset, lift);
            L.liftedForClearance += lift > 0.0f;
            L.maxLift = std::max(L.maxLift, lift);
            L.positions.push_back(p);
            L.valid.push_back(p.y > hf.surfaceHeight(x, z) ? 1 : 0);
        }

    // Occupancy: cubic cells of the smaller probe spacing (or, for a single probe, of the
    // larger footprint side) spanning the probes' columns from the lowest ground to above the
    // highest probe. A cell with any part above the terrain maps to the nearest probe column (an
    // object standing on the ground finds its probe whichever cell it lands in); a cell wholly
    // inside the terrain holds -1.
    float cell = 0.0f;
    if (spacing.x > 0.0f && spacing.z > 0.0f) cell = std::min(spacing.x, spacing.z);
    else cell = std::max(spacing.x, spacing.z);
    if (!(cell > 0.0f)) cell = std::max({spanX, spanZ, 1.0f});
    const float halfX = nx > 1 ? 0.5f * spacing.x : 0.5f * cell;
    const float halfZ = nz > 1 ? 0.5f * spacing.z : 0.5f * cell;
    const float x0 = first.x - halfX, x1 = first.x + spacing.x * float(nx - 1) + halfX;
    const float z0 = first.z - halfZ, z1 = first.z + spacing.z * float(nz - 1) + halfZ;
    float yMin = hf.minHeight(), yMax = hf.maxHeight();
    for (const auto& p : L.positions) yMax = std::max(yMax, p.y), yMin = std::min(yMin, p.y);
    const double dimsD[3] = {std::ceil((x1 - x0) / cell - 1e-4),
                             std::ceil((yMax - yMin) / cell - 1e-4) + 1.0,
                             std::ceil((z1 - z0) / cell - 1e-4)};
    const double cells = std::max(dimsD[0], 1.0) * std::max(dimsD[1], 1.0) * std::max(dimsD[2], 1.0);
    if (cells > double(kMaxOccupancyCells))
        throw PlacementError(where + ": occupancy grid of " + num(cells) +
                             " cells exceeds " + std::to_string(kMaxOccupancyCells) +
                             "; use fewer, wider-spaced probes");
    // The cells are cubes of the smaller spacing: on a long thin footprint that spacing is metres
    // while the other side and the relief are kilometres, and the file holds millions of cells for
    // a handful of probes (a 512 x 2 raster wrote 18.5 MB for 64).
    const double probes = double(nx) * double(nz);
    if (cells > double(kMaxOccupancyCellsPerProbe) * probes) {
        const bool alongZ = nx > 1 && nz > 1 ? spacing.z < spacing.x : nz > 1;
        throw PlacementError(where + ": occupancy grid of " + num(cells) + " cells (" + num(dimsD[0]) + " x " +
                             num(dimsD[1]) + " x " + num(dimsD[2]) + " of " + num(cell) + " m) for " +
                             num(probes) + " probes, more than " + std::to_string(kMaxOccupancyCellsPerProbe) +
                             " a probe: its cells are the " + num(cell) + " m spacing along " +
                             (alongZ ? "z" : "x") + "; use fewer probes along " + (alongZ ? "z" : "x"));
    }
    L.cellSize = cell;
    L.cellDims = {uint32_t(std::max(dimsD[0], 1.0)), uint32_t(std::max(dimsD[1], 1.0)),
                  uint32_t(std::max(dimsD[2], 1.0))};
    L.cellOrigin = glm::vec3(x0, yMin, z0);
    L.cellProbe.assign(size_t(L.cellDims[0]) * L.cellDims[1] * L.cellDims[2], -1);
    for (uint32_t cz = 0; cz < L.cellDims[2]; ++cz)
        for (uint32_t cx = 0; cx < L.cellDims[0]; ++cx) {
            const float x = x0 + (float(cx) + 0.5f) * cell, z = z0 + (float(cz) + 0.5f) * cell;
            const int i = nx > 1 ? std::clamp(int(std::lround((x - first.x) / spacing.x)), 0, nx - 1) : 0;
            const int k = nz > 1 ? std::clamp(int(std::lround((z - first.z) / spacing.z)), 0, nz - 1) : 0;
            const int probe = k * nx + i;
            if (!L.valid[size_t(probe)]) continue;
            const float lowest = surfaceRange(hf, x - 0.5 * cell, x + 0.5 * cell, z - 0.5 * cell,
                                              z + 0.5 * cell).lo;
            for (uint32_t cy = 0; cy < L.cellDims[1]; ++cy) {
                const double top = double(yMin) + double(cy + 1) * cell;
                if (top > lowest)
                    L.cellProbe[cx + size_t(cy) * L.cellDims[0] +
                                size_t(cz) * L.cellDims[0] * L.cellDims[1]] = probe;
            }
        }
    return L;
}

// Uniform box grid: one probe at the centre of each cubic cell.
ProbeLayout placeBoxGrid(const ProbeVolumeSettings& v, const Heightfield& hf) {
    ProbeLayout L;
    const int nx = v.gridDims[0], ny = v.gridDims[1], nz = v.gridDims[2];
    L.probeDims = {nx, ny, nz};
    const BoxGridFrame frame = boxGridFrame(v, hf);
    const float cell = frame.cell;
    const glm::vec3 origin = frame.origin;
    L.spacing = glm::vec3(cell);
    L.cellSize = cell;
    L.cellOrigin = origin;
    L.cellDims = {uint32_t(nx), uint32_t(ny), uint32_t(nz)};
    L.cellProbe.assign(size_t(nx) * ny * nz, -1);
    for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y)
            for (int x = 0; x < nx; ++x) {
                const glm::vec3 p = origin + cell * glm::vec3(float(x) + 0.5f, float(y) + 0.5f,
                                                              float(z) + 0.5f);
                const bool above = p.y > hf.surfaceHeight(p.x, p.z);
                const int index = int(L.positions.size());
                L.positions.push_back(p);
                L.valid.push_back(above ? 1 : 0);
                if (above) L.cellProbe[x + size_t(y) * nx + size_t(z) * nx * ny] = index;
            }
    // A cell partly above the ground whose centre probe is inside the terrain points at the first
    // valid probe above it in its column (as terrain grids and adaptive minimum cells do), so an
    // object standing on the ground there still finds a probe. Cells wholly inside keep -1.
    for (int z = 0; z < nz; ++z)
        for (int x = 0; x < nx; ++x) {
            const double x0 = origin.x + cell * x, z0 = origin.z + cell * z;
            const float lowest = surfaceRange(hf, x0, x0 + cell, z0, z0 + cell).lo;
            for (int y = 0; y < ny; ++y) {
                const size_t c = x + size_t(y) * nx + size_t(z) * nx * ny;
                if (L.cellProbe[c] >= 0 || !(origin.y + cell * float(y + 1) > lowest)) continue;
                for (int above = y + 1; above < ny; ++above) {
                    const int32_t probe = L.cellProbe[x + size_t(above) * nx + size_t(z) * nx * ny];
                    if (probe >= 0 && L.valid[size_t(probe)]) {
                        L.cellProbe[c] = probe;
                        ++L.borrowedCells;
                        break;
                    }
                }
            }
        }
    // Box placement order is x fastest, then y, then z, matching the occupancy layout.
    return L;
}

}  // namespace

float defaultFallbackBlendDistance(glm::vec2 spacing, glm::vec2 extent) {
    const float x = spacing.x > 0.0f ? spacing.x : extent.x;
    const float z = spacing.y > 0.0f ? spacing.y : extent.y;
    return 2.0f * std::min(x, z);
}

float liftClearOfSelfHits(const Heightfield& hf, const glm::vec3& p) {
    // The distance is taken at a point a little above p, as the lift raises it (it grows with
    // the coordinates' magnitude).
    const double r = 2.0 * double(HeightfieldTracer::minDistance(p + glm::vec3(0.0f, 1.0f, 0.0f)));
    const float hi = surfaceRange(hf, p.x - r, p.x + r, p.z - r, p.z + r).hi;
    const float clear = float(double(hi) + r);
    return clear > p.y ? std::nextafter(clear, INFINITY) : p.y;
}

glm::vec3 probeAboveSurface(const Heightfield& hf, float x, float z, double offset, float& lift) {
    const float ground = hf.surfaceHeight(x, z);
    glm::vec3 p(x, ground + float(offset), z);
    // An offset below the float spacing at this height would round onto the surface.
    if (offset > 0.0 && !(p.y > ground)) p.y = std::nextafter(ground, INFINITY);
    lift = 0.0f;
    if (p.y > ground) {
        const float clear = liftClearOfSelfHits(hf, p);
        lift = clear - p.y;
        p.y = clear;
    }
    return p;
}

TerrainGridFrame terrainGridFrame(const ProbeVolumeSettings& v, const Heightfield& hf) {
    const int nx = v.gridDims[0], nz = v.gridDims[2];
    const float spanX = hf.maxX() - hf.minX(), spanZ = hf.maxZ() - hf.minZ();
    TerrainGridFrame f;
    if (v.spacing) {
        f.spacing = glm::vec2(v.spacing->x, v.spacing->z);
    } else {
        f.spacing.x = nx > 1 ? spanX / float(nx - 1) : 0.0f;
        f.spacing.y = nz > 1 ? spanZ / float(nz - 1) : 0.0f;
    }
    if (v.origin) {
        f.first = glm::vec2(v.origin->x, v.origin->z);
    } else {
        // Centred: auto-span reaches the edges exactly; explicit spacing is centred on the terrain.
        const glm::vec2 centre(0.5f * (hf.minX() + hf.maxX()), 0.5f * (hf.minZ() + hf.maxZ()));
        f.first = centre - 0.5f * f.spacing * glm::vec2(float(nx - 1), float(nz - 1));
    }
    return f;
}

BoxGridFrame boxGridFrame(const ProbeVolumeSettings& v, const Heightfield& hf) {
    const int nx = v.gridDims[0], nz = v.gridDims[2];
    const float spanX = hf.maxX() - hf.minX(), spanZ = hf.maxZ() - hf.minZ();
    BoxGridFrame f;
    f.cell = v.spacing ? v.spacing->x : std::max({spanX / float(nx), spanZ / float(nz), 1e-3f});
    // Unset: centred on the footprint, from the lowest ground up.
    f.origin = v.origin ? *v.origin
                        : glm::vec3(0.5f * (hf.minX() + hf.maxX()) - 0.5f * f.cell * float(nx), hf.minHeight(),
                                    0.5f * (hf.minZ() + hf.maxZ()) - 0.5f * f.cell * float(nz));
    return f;
}

AdaptiveBox adaptiveBox(const ProbeVolumeSettings& v, const Heightfield& hf) {
    AdaptiveBox b;
    b.origin = v.origin ? glm::dvec3(*v.origin) : glm::dvec3(hf.minX(), hf.minHeight(), hf.minZ());
    b.size = v.adaptive.size ? glm::dvec3(*v.adaptive.size)
                             : glm::dvec3(double(hf.maxX()) - hf.minX(),
                                          double(hf.maxHeight()) + v.adaptive.heightRange - b.origin.y,
                                          double(hf.maxZ()) - hf.minZ());
    return b;
}

ProbeLayout placeProbes(const ProbeVolumeSettings& v, const Heightfield& hf) {
    ProbeLayout L = v.placement == ProbePlacement::Box ? placeBoxGrid(v, hf)
                    : refinedByError(v.placement)    ? placeAdaptive(v, hf)
                                                     : placeTerrainGrid(v, hf);
    if (v.fallbackBlendDistance) {
        L.fallbackBlendDistance = float(*v.fallbackBlendDistance);
    } else if (v.placement == ProbePlacement::Terrain) {
        // An explicit spacing on a one-probe axis places nothing: that axis has no spacing.
        const glm::vec2 spacing(L.probeDims[0] > 1 ? L.spacing.x : 0.0f, L.probeDims[2] > 1 ? L.spacing.z : 0.0f);
        const glm::vec2 extent(std::max(hf.maxX() - hf.minX(), float(hf.cellSizeX())),
                               std::max(hf.maxZ() - hf.minZ(), float(hf.cellSizeZ())));
        L.fallbackBlendDistance = defaultFallbackBlendDistance(spacing, extent);
    } else {
        // Box and adaptive volumes: cubic cells, each probe standing for one (the smallest).
        L.fallbackBlendDistance = defaultFallbackBlendDistance(glm::vec2(L.spacing.x), glm::vec2(L.spacing.x));
    }
    return L;
}

}  // namespace terralux
