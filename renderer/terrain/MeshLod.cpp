#include "terrain/MeshLod.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

#include <glm/geometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

namespace terralux::lod {

std::vector<uint32_t> kept(uint32_t n, uint32_t step) {
    std::vector<uint32_t> k;
    if (n == 0) return k;
    step = std::max(step, 1u);
    for (uint32_t i = 0; i < n; i += step) k.push_back(i);
    if (k.back() != n - 1) k.push_back(n - 1);
    return k;
}

void appendTriangles(std::vector<uint32_t>& indices, uint32_t nc, const std::vector<uint32_t>& kc,
                     const std::vector<uint32_t>& kr) {
    for (size_t r = 0; r + 1 < kr.size(); ++r)
        for (size_t c = 0; c + 1 < kc.size(); ++c) {
            const uint32_t v00 = kr[r] * nc + kc[c], v10 = kr[r] * nc + kc[c + 1];
            const uint32_t v01 = kr[r + 1] * nc + kc[c], v11 = kr[r + 1] * nc + kc[c + 1];
            indices.insert(indices.end(), {v00, v01, v11, v00, v11, v10});
        }
}

namespace {

// Per grid line from k.front() to k.back(): the kept cell holding it and where in that cell (0..1).
struct Span {
    std::vector<uint32_t> cell;
    std::vector<double> f;
};

// With `at` (the lines' world coordinates), where in the cell is measured in the world, as the
// drawn triangles interpolate; without, in lines (the same on an evenly spaced grid).
Span spans(const std::vector<uint32_t>& k, std::span<const float> at) {
    const uint32_t n = k.back() - k.front() + 1;
    Span s{std::vector<uint32_t>(n), std::vector<double>(n)};
    size_t cell = 0;
    for (uint32_t i = k.front(); i <= k.back(); ++i) {
        while (cell + 2 < k.size() && i > k[cell + 1]) ++cell;
        s.cell[i - k.front()] = uint32_t(cell);
        s.f[i - k.front()] = at.empty() ? double(i - k[cell]) / double(k[cell + 1] - k[cell])
                                        : (double(at[i]) - at[k[cell]]) / (double(at[k[cell + 1]]) - at[k[cell]]);
    }
    return s;
}

}  // namespace

double gridError(std::span<const float> heights, uint32_t nc, const std::vector<uint32_t>& kc,
                 const std::vector<uint32_t>& kr, std::span<const float> colX, std::span<const float> rowZ) {
    if (kc.size() < 2 || kr.size() < 2) return 0.0;
    const uint32_t c0 = kc.front(), r0 = kr.front();
    const Span u = spans(kc, colX), v = spans(kr, rowZ);
    auto h = [&](uint32_t c, uint32_t r) { return double(heights[size_t(r) * nc + c]); };
    return tbb::parallel_reduce(
        tbb::blocked_range<uint32_t>(r0, kr.back() + 1), 0.0,
        [&](const tbb::blocked_range<uint32_t>& rows, double worst) {
            for (uint32_t r = rows.begin(); r != rows.end(); ++r) {
                const uint32_t cell = v.cell[r - r0];
                const uint32_t ra = kr[cell], rb = kr[cell + 1];
                const double fv = v.f[r - r0];
                for (uint32_t c = c0; c <= kc.back(); ++c) {
                    const uint32_t cc = u.cell[c - c0];
                    const uint32_t ca = kc[cc], cb = kc[cc + 1];
                    const double fu = u.f[c - c0];
                    const double h00 = h(ca, ra), h10 = h(cb, ra), h01 = h(ca, rb), h11 = h(cb, rb);
                    // The triangle (ca, ra), (ca, rb), (cb, rb) where fu <= fv, else
                    // (ca, ra), (cb, rb), (cb, ra): the tracer's and the mesh's split.
                    const double s = fu <= fv ? h00 + fu * (h11 - h01) + fv * (h01 - h00)
                                              : h00 + fu * (h10 - h00) + fv * (h11 - h10);
                    worst = std::max(worst, std::abs(h(c, r) - s));
                }
            }
            return worst;
        },
        [](double a, double b) { return std::max(a, b); });
}

double distanceToBox(const glm::vec3& p, const glm::vec3& lo, const glm::vec3& hi) {
    const glm::dvec3 d = glm::max(glm::max(glm::dvec3(lo) - glm::dvec3(p), glm::dvec3(p) - glm::dvec3(hi)), glm::dvec3(0.0));
    return glm::length(d);
}

double screenPixels(double metres, double distance, double fovY, double heightPixels) {
    if (metres <= 0.0) return 0.0;
    if (!(distance > 0.0)) return std::numeric_limits<double>::infinity();
    return metres / distance * heightPixels / (2.0 * std::tan(0.5 * fovY));
}

namespace {

// Boundaries of patches of about `cells` cells over n vertices: every `cells`, the last patch
// taking the remainder (so none is smaller than `cells` where the grid is not).
std::vector<uint32_t> boundaries(uint32_t n, uint32_t cells) {
    std::vector<uint32_t> b{0};
    const uint32_t last = n - 1, count = std::max(last / cells, 1u);
    for (uint32_t i = 1; i < count; ++i) b.push_back(i * cells);
    b.push_back(last);
    return b;
}

// `from`..`to` at `step` (relative to `from`), `to` always.
std::vector<uint32_t> keptRange(uint32_t from, uint32_t to, uint32_t step) {
    std::vector<uint32_t> k = kept(to - from + 1, step);
    for (uint32_t& v : k) v += from;
    return k;
}

// Levels a span of `cells` cells has: steps up to half of it (two cells a side at least).
uint8_t coarsestLevel(uint32_t cells) {
    uint8_t l = 0;
    while (2u * stepOf(uint8_t(l + 1)) <= cells) ++l;
    return l;
}

}  // namespace

Patches buildPatches(std::span<const float> heights, uint32_t nc, uint32_t nr, std::span<const float> colX,
                     std::span<const float> rowZ, uint32_t patchCells) {
    Patches p;
    p.nc = nc;
    p.nr = nr;
    p.x.assign(colX.begin(), colX.end());
    p.z.assign(rowZ.begin(), rowZ.end());
    if (nc < 2 || nr < 2) return p;
    p.cols = boundaries(nc, std::max(patchCells, 2u));
    p.rows = boundaries(nr, std::max(patchCells, 2u));
    const uint32_t n = p.count();
    p.coarsest.resize(n);
    p.lo.resize(n);
    p.hi.resize(n);
    for (uint32_t j = 0; j < p.patchesZ(); ++j)
        for (uint32_t i = 0; i < p.patchesX(); ++i) {
            const uint32_t k = j * p.patchesX() + i;
            p.coarsest[k] = std::min(coarsestLevel(p.cols[i + 1] - p.cols[i]), coarsestLevel(p.rows[j + 1] - p.rows[j]));
            p.levels = std::max(p.levels, uint32_t(p.coarsest[k]) + 1);
        }
    p.error.assign(size_t(n) * p.levels, 0.0);
    tbb::parallel_for(uint32_t(0), n, [&](uint32_t k) {
        const uint32_t i = k % p.patchesX(), j = k / p.patchesX();
        const uint32_t c0 = p.cols[i], c1 = p.cols[i + 1], r0 = p.rows[j], r1 = p.rows[j + 1];
        float yLo = heights[size_t(r0) * nc + c0], yHi = yLo;
        for (uint32_t r = r0; r <= r1; ++r)
            for (uint32_t c = c0; c <= c1; ++c) {
                yLo = std::min(yLo, heights[size_t(r) * nc + c]);
                yHi = std::max(yHi, heights[size_t(r) * nc + c]);
            }
        p.lo[k] = glm::vec3(std::min(colX[c0], colX[c1]), yLo, std::min(rowZ[r0], rowZ[r1]));
        p.hi[k] = glm::vec3(std::max(colX[c0], colX[c1]), yHi, std::max(rowZ[r0], rowZ[r1]));
        for (uint32_t l = 0; l < p.levels; ++l) {
            // Levels past the patch's coarsest stand at its coarsest, never chosen.
            const uint32_t step = stepOf(uint8_t(std::min<uint32_t>(l, p.coarsest[k])));
            p.error[size_t(k) * p.levels + l] =
                step > 1 ? gridError(heights, nc, keptRange(c0, c1, step), keptRange(r0, r1, step), colX, rowZ) : 0.0;
        }
    });
    return p;
}

std::vector<uint8_t> chooseLevels(const Patches& p, const glm::vec3& eye, double fovY, double heightPixels,
                                  double maxPixels) {
    std::vector<uint8_t> levels(p.count(), 0);
    for (uint32_t k = 0; k < p.count(); ++k) {
        const double distance = distanceToBox(eye, p.lo[k], p.hi[k]);
        // A finer level can leave out more than a coarser one (its vertices are not the coarser's
        // plus some: every 8th keeps a spike that every 16th skips). The level taken is the
        // coarsest with every finer one within the pixel too, so a patch drawn finer than it
        // chose (settleRings) stays within it.
        uint8_t chosen = 0;
        for (uint8_t l = 1; l <= p.coarsest[k]; ++l) {
            if (screenPixels(p.error[size_t(k) * p.levels + l], distance, fovY, heightPixels) > maxPixels) break;
            chosen = l;
        }
        levels[k] = chosen;
    }
    return levels;
}

namespace {

struct GridPoint {
    uint32_t c, r;
};

// The strip between two runs of vertices along one axis, `outer` on the patch's edge and `inner`
// one ring of cells in, from one shared rung (outer.front()-inner.front()) to the other, each
// triangle counter-clockwise from above. At a tie the diagonal the plain grid would draw is
// taken: innerFirst says it runs from the outer vertex to the next inner one.
void zip(std::vector<uint32_t>& out, uint32_t nc, const std::vector<GridPoint>& outer,
         const std::vector<GridPoint>& inner, bool alongColumns, bool innerFirst) {
    auto t = [&](const GridPoint& g) { return alongColumns ? g.c : g.r; };
    auto index = [&](const GridPoint& g) { return g.r * nc + g.c; };
    auto emit = [&](const GridPoint& a, const GridPoint& b, const GridPoint& c) {
        // Counter-clockwise from above is negative area in (c, r) (rows run along +z).
        const int64_t area = (int64_t(b.c) - a.c) * (int64_t(c.r) - a.r) - (int64_t(c.c) - a.c) * (int64_t(b.r) - a.r);
        if (area == 0) return;
        if (area < 0)
            out.insert(out.end(), {index(a), index(b), index(c)});
        else
            out.insert(out.end(), {index(a), index(c), index(b)});
    };
    size_t i = 0, j = 0;
    while (i + 1 < outer.size() || j + 1 < inner.size()) {
        const bool outerNext = j + 1 >= inner.size() ||
                               (i + 1 < outer.size() && (t(outer[i + 1]) < t(inner[j + 1]) ||
                                                         (t(outer[i + 1]) == t(inner[j + 1]) && !innerFirst)));
        if (outerNext) {
            emit(outer[i], outer[i + 1], inner[j]);
            ++i;
        } else {
            emit(outer[i], inner[j + 1], inner[j]);
            ++j;
        }
    }
}

// Appends the grid through columns kc and rows kr of an nc-wide vertex grid, its edges drawn
// through the runs north (along row kr.front()), south (kr.back()), west (column kc.front()) and
// east (kc.back()), each from corner to corner; where a run is not the kept lines the ring of
// cells along that edge is zipped to it. Returns whether any edge is zipped.
bool appendZippedGrid(std::vector<uint32_t>& indices, uint32_t nc, const std::vector<uint32_t>& kc,
                      const std::vector<uint32_t>& kr, const std::vector<uint32_t>& north,
                      const std::vector<uint32_t>& south, const std::vector<uint32_t>& west,
                      const std::vector<uint32_t>& east) {
    // (A grid one cell across has no ring; its neighbours along its row or column are one cell
    // across too, so they all stand at the same step and nothing is zipped.)
    if ((north == kc && south == kc && west == kr && east == kr) || kc.size() < 3 || kr.size() < 3) {
        appendTriangles(indices, nc, kc, kr);
        return false;
    }
    // The ring of cells along the edges zipped to the edges' vertices, the inside as a
    // plain grid. Its inner runs are the second and second-last kept lines.
    const std::vector<uint32_t> ic(kc.begin() + 1, kc.end() - 1), ir(kr.begin() + 1, kr.end() - 1);
    appendTriangles(indices, nc, ic, ir);
    auto row = [](const std::vector<uint32_t>& cs, uint32_t r) {
        std::vector<GridPoint> g;
        for (uint32_t c : cs) g.push_back({c, r});
        return g;
    };
    auto column = [](const std::vector<uint32_t>& rs, uint32_t c) {
        std::vector<GridPoint> g;
        for (uint32_t r : rs) g.push_back({c, r});
        return g;
    };
    // The plain grid's diagonal (c, r)-(c+1, r+1) runs from the outer vertex to the next
    // inner one on the north and west edges, and from the inner vertex to the next outer
    // one on the south and east edges.
    zip(indices, nc, row(north, kr.front()), row(ic, ir.front()), true, true);
    zip(indices, nc, row(south, kr.back()), row(ic, ir.back()), true, false);
    zip(indices, nc, column(west, kc.front()), column(ir, ic.front()), false, true);
    zip(indices, nc, column(east, kc.back()), column(ir, ic.back()), false, false);
    return true;
}

// Appends patch (i, j)'s triangles at its level, zipped to coarser neighbours; returns whether
// any edge is zipped. A patch drawn from the source grid (detail[k] >= 0) gives neither
// triangles nor border segments (its own skirt hangs from its own border edges).
bool appendPatch(std::vector<uint32_t>& indices, const Patches& p, std::span<const uint8_t> levels, uint32_t i,
                 uint32_t j, std::vector<uint32_t>* borderSegments, std::span<const int8_t> detail = {}) {
    const uint32_t px = p.patchesX(), pz = p.patchesZ(), nc = p.nc;
    auto level = [&](int64_t a, int64_t b) -> int {
        if (a < 0 || b < 0 || a >= int64_t(px) || b >= int64_t(pz)) return -1;  // outside: the border
        return levels[size_t(b) * px + size_t(a)];
    };
    if (!detail.empty() && detail[size_t(j) * px + i] >= 0) return false;
    const int own = level(i, j);
    const uint32_t step = stepOf(uint8_t(own));
    const uint32_t c0 = p.cols[i], c1 = p.cols[i + 1], r0 = p.rows[j], r1 = p.rows[j + 1];
    const std::vector<uint32_t> kc = keptRange(c0, c1, step), kr = keptRange(r0, r1, step);
    // Each edge at the coarser of the two patches' steps (a border edge at its own).
    auto edgeStep = [&](int neighbour) { return stepOf(uint8_t(std::max(own, neighbour))); };
    const uint32_t sN = edgeStep(level(i, int64_t(j) - 1)), sS = edgeStep(level(i, j + 1));
    const uint32_t sW = edgeStep(level(int64_t(i) - 1, j)), sE = edgeStep(level(i + 1, j));
    if (borderSegments) {
        auto segments = [&](const std::vector<uint32_t>& run, bool alongColumns, uint32_t fixed) {
            for (size_t k = 0; k + 1 < run.size(); ++k) {
                const uint32_t a = alongColumns ? fixed * nc + run[k] : run[k] * nc + fixed;
                const uint32_t b = alongColumns ? fixed * nc + run[k + 1] : run[k + 1] * nc + fixed;
                borderSegments->insert(borderSegments->end(), {a, b});
            }
        };
        if (j == 0) segments(keptRange(c0, c1, sN), true, r0);
        if (j + 1 == pz) segments(keptRange(c0, c1, sS), true, r1);
        if (i == 0) segments(keptRange(r0, r1, sW), false, c0);
        if (i + 1 == px) segments(keptRange(r0, r1, sE), false, c1);
    }
    return appendZippedGrid(indices, nc, kc, kr, keptRange(c0, c1, sN), keptRange(c0, c1, sS), keptRange(r0, r1, sW),
                            keptRange(r0, r1, sE));
}

// The largest |h - s| over the grid vertices under each of `tris` (indices r * nc + c, less
// `base`), s the triangle's plane through its corners, in world (x(c), z(r)).
template <class H, class X, class Z>
double trianglesError(const std::vector<uint32_t>& tris, uint32_t nc, uint32_t base, H h, X x, Z z) {
    double worst = 0.0;
    for (size_t t = 0; t + 2 < tris.size(); t += 3) {
        uint32_t c[3], r[3];
        for (int v = 0; v < 3; ++v) c[v] = (tris[t + v] - base) % nc, r[v] = (tris[t + v] - base) / nc;
        const double x0 = x(c[0]), z0 = z(r[0]);
        const double ax = x(c[1]) - x0, az = z(r[1]) - z0, bx = x(c[2]) - x0, bz = z(r[2]) - z0;
        const double det = ax * bz - az * bx;
        if (det == 0.0) continue;
        const double h0 = h(c[0], r[0]), h1 = h(c[1], r[1]), h2 = h(c[2], r[2]);
        const double eps = 1e-9;
        for (uint32_t rr = std::min({r[0], r[1], r[2]}); rr <= std::max({r[0], r[1], r[2]}); ++rr)
            for (uint32_t cc = std::min({c[0], c[1], c[2]}); cc <= std::max({c[0], c[1], c[2]}); ++cc) {
                const double dx = x(cc) - x0, dz = z(rr) - z0;
                const double u = (dx * bz - dz * bx) / det, v = (ax * dz - az * dx) / det;
                if (u < -eps || v < -eps || u + v > 1.0 + eps) continue;
                worst = std::max(worst, std::abs(h(cc, rr) - (h0 + u * (h1 - h0) + v * (h2 - h0))));
            }
    }
    return worst;
}

}  // namespace

void appendPatchTriangles(std::vector<uint32_t>& indices, const Patches& p, std::span<const uint8_t> levels,
                          std::vector<uint32_t>* borderSegments, std::span<const int8_t> detail) {
    if (p.cols.size() < 2 || p.rows.size() < 2) return;
    for (uint32_t j = 0; j < p.patchesZ(); ++j)
        for (uint32_t i = 0; i < p.patchesX(); ++i) appendPatch(indices, p, levels, i, j, borderSegments, detail);
}

SourceSpan sourceSpan(const Patches& p, const SourceGrid& g, uint32_t k) {
    const uint32_t i = k % p.patchesX(), j = k / p.patchesX();
    return {g.col[p.cols[i]], g.col[p.cols[i + 1]], g.row[p.rows[j]], g.row[p.rows[j + 1]]};
}

std::vector<uint32_t> detailVertices(const Patches& p, const SourceGrid& g, uint32_t k, uint8_t d) {
    const SourceSpan s = sourceSpan(p, g, k);
    const std::vector<uint32_t> kc = keptRange(0, s.nc() - 1, stepOf(d)), kr = keptRange(0, s.nr() - 1, stepOf(d));
    std::vector<uint32_t> v;
    size_t next = 0;  // the next kept row
    for (uint32_t r = 0; r < s.nr(); ++r) {
        const bool keptRow = next < kr.size() && kr[next] == r;
        if (keptRow) ++next;
        if (r == 0 || r + 1 == s.nr()) {
            for (uint32_t c = 0; c < s.nc(); ++c) v.push_back(r * s.nc() + c);
        } else if (keptRow) {
            for (uint32_t c : kc) v.push_back(r * s.nc() + c);
        } else {
            v.push_back(r * s.nc());
            v.push_back(r * s.nc() + s.nc() - 1);
        }
    }
    return v;
}

size_t detailVertexCount(const Patches& p, const SourceGrid& g, uint32_t k, uint8_t d) {
    const SourceSpan s = sourceSpan(p, g, k);
    const size_t kc = keptRange(0, s.nc() - 1, stepOf(d)).size(), kr = keptRange(0, s.nr() - 1, stepOf(d)).size();
    return 2 * size_t(s.nc()) + (kr - 2) * kc + (size_t(s.nr()) - kr) * 2;
}

namespace {

// Detail patch k's triangles in its span's own indices.
std::vector<uint32_t> detailTriangles(const Patches& p, const SourceGrid& g, std::span<const uint8_t> levels,
                                      std::span<const int8_t> detail, uint32_t k) {
    const uint32_t px = p.patchesX(), pz = p.patchesZ(), i = k % px, j = k / px;
    const SourceSpan s = sourceSpan(p, g, k);
    const int own = detail[k];
    const std::vector<uint32_t> kc = keptRange(0, s.nc() - 1, stepOf(uint8_t(own)));
    const std::vector<uint32_t> kr = keptRange(0, s.nr() - 1, stepOf(uint8_t(own)));
    // One edge's run in the span's own coordinates, along columns (north, south) or rows.
    auto run = [&](int64_t a, int64_t b, bool alongColumns) {
        const uint32_t n = alongColumns ? s.nc() : s.nr();
        const bool outside = a < 0 || b < 0 || a >= int64_t(px) || b >= int64_t(pz);
        if (outside) return keptRange(0, n - 1, stepOf(uint8_t(own)));
        const size_t nk = size_t(b) * px + size_t(a);
        if (detail[nk] >= 0) return keptRange(0, n - 1, stepOf(uint8_t(std::max(own, int(detail[nk])))));
        // A drawn neighbour's vertices at its level.
        const uint32_t drawnStep = stepOf(levels[nk]);
        const std::vector<uint32_t>& bounds = alongColumns ? p.cols : p.rows;
        const std::vector<uint32_t>& source = alongColumns ? g.col : g.row;
        const uint32_t first = alongColumns ? bounds[i] : bounds[j], last = alongColumns ? bounds[i + 1] : bounds[j + 1];
        std::vector<uint32_t> r = keptRange(first, last, drawnStep);
        for (uint32_t& v : r) v = source[v] - source[first];
        return r;
    };
    std::vector<uint32_t> tris;
    appendZippedGrid(tris, s.nc(), kc, kr, run(i, int64_t(j) - 1, true), run(i, int64_t(j) + 1, true),
                     run(int64_t(i) - 1, j, false), run(int64_t(i) + 1, j, false));
    return tris;
}

// A span's own index to its place in `held` (detailVertices, ascending).
uint32_t heldIndex(const std::vector<uint32_t>& held, uint32_t v) {
    return uint32_t(std::lower_bound(held.begin(), held.end(), v) - held.begin());
}

}  // namespace

void appendDetailPatch(std::vector<uint32_t>& indices, const Patches& p, const SourceGrid& g,
                       std::span<const uint8_t> levels, std::span<const int8_t> detail, uint32_t k, uint32_t base) {
    const std::vector<uint32_t> held = detailVertices(p, g, k, uint8_t(detail[k]));
    std::vector<uint32_t> place(sourceSpan(p, g, k).vertices(), 0);
    for (size_t m = 0; m < held.size(); ++m) place[held[m]] = base + uint32_t(m);
    const std::vector<uint32_t> tris = detailTriangles(p, g, levels, detail, k);
    indices.reserve(indices.size() + tris.size());
    for (uint32_t v : tris) indices.push_back(place[v]);
}

std::vector<DetailTwin> detailSkirtTwins(const Patches& p, const SourceGrid& g, uint32_t k, uint8_t d) {
    const uint32_t px = p.patchesX(), pz = p.patchesZ(), i = k % px, j = k / px;
    const SourceSpan s = sourceSpan(p, g, k);
    std::vector<DetailTwin> t;
    if (j == 0)
        for (uint32_t c : keptRange(s.c0, s.c1, stepOf(d))) t.push_back({c, s.r0, 0, -1});
    if (j + 1 == pz)
        for (uint32_t c : keptRange(s.c0, s.c1, stepOf(d))) t.push_back({c, s.r1, 0, 1});
    if (i == 0)
        for (uint32_t r : keptRange(s.r0, s.r1, stepOf(d))) t.push_back({s.c0, r, -1, 0});
    if (i + 1 == px)
        for (uint32_t r : keptRange(s.r0, s.r1, stepOf(d))) t.push_back({s.c1, r, 1, 0});
    return t;
}

void appendDetailSkirt(std::vector<uint32_t>& indices, const Patches& p, const SourceGrid& g,
                       std::span<const int8_t> detail, uint32_t k, uint32_t base) {
    const uint32_t px = p.patchesX(), pz = p.patchesZ(), i = k % px, j = k / px;
    const SourceSpan s = sourceSpan(p, g, k);
    const uint8_t d = uint8_t(detail[k]);
    const std::vector<uint32_t> held = detailVertices(p, g, k, d);
    uint32_t twin = base + uint32_t(held.size());
    // One border edge: its vertices at the patch's step and their twins, from `twin` on.
    auto edge = [&](bool alongColumns, uint32_t fixed) {
        const std::vector<uint32_t> run = keptRange(0, (alongColumns ? s.nc() : s.nr()) - 1, stepOf(d));
        auto vertex = [&](uint32_t t) { return base + heldIndex(held, alongColumns ? fixed * s.nc() + t : t * s.nc() + fixed); };
        for (size_t m = 0; m + 1 < run.size(); ++m) {
            const uint32_t a = vertex(run[m]), b = vertex(run[m + 1]), ta = twin + uint32_t(m), tb = ta + 1;
            indices.insert(indices.end(), {a, b, tb, a, tb, ta});
        }
        twin += uint32_t(run.size());
    };
    if (j == 0) edge(true, 0);
    if (j + 1 == pz) edge(true, s.nr() - 1);
    if (i == 0) edge(false, 0);
    if (i + 1 == px) edge(false, s.nc() - 1);
}

double detailSurfaceError(const Patches& p, const SourceGrid& g, std::span<const uint8_t> levels,
                          std::span<const int8_t> detail, uint32_t k, std::span<const float> heights) {
    const std::vector<uint32_t> tris = detailTriangles(p, g, levels, detail, k);
    const SourceSpan s = sourceSpan(p, g, k);
    return trianglesError(
        tris, s.nc(), 0, [&](uint32_t c, uint32_t r) { return double(heights[size_t(s.r0 + r) * g.nc + s.c0 + c]); },
        [&](uint32_t c) { return double(g.x[s.c0 + c]); }, [&](uint32_t r) { return double(g.z[s.r0 + r]); });
}

std::vector<size_t> allocateDetail(std::span<const DetailCandidate> candidates, size_t budget, double maxPixels) {
    std::vector<size_t> state(candidates.size(), 0);
    size_t need = 0;
    for (const DetailCandidate& c : candidates) need += c.vertices[c.target];
    if (need <= budget) {
        for (size_t m = 0; m < candidates.size(); ++m) state[m] = candidates[m].target;
        return state;
    }
    std::priority_queue<std::pair<double, size_t>> worst;
    for (size_t m = 0; m < candidates.size(); ++m) worst.push({candidates[m].pixels[0], m});
    size_t used = 0;
    while (!worst.empty() && worst.top().first > maxPixels) {
        const size_t m = worst.top().second;
        const DetailCandidate& c = candidates[m];
        // Its cheapest finer state that is nearer (a state no nearer is skipped: it would spend
        // vertices and lower nothing).
        size_t next = state[m] + 1;
        while (next < c.pixels.size() && c.pixels[next] >= c.pixels[state[m]]) ++next;
        worst.pop();
        // Where it has none, or it does not fit, the largest stays what it is; the budget left
        // still brings the others nearer.
        if (next >= c.pixels.size()) continue;
        const size_t more = c.vertices[next] - c.vertices[state[m]];
        if (used + more > budget) continue;
        used += more;
        state[m] = next;
        worst.push({c.pixels[state[m]], m});
    }
    return state;
}

double detailLevelError(const Patches& p, const SourceGrid& g, uint32_t k, uint8_t d, std::span<const float> heights) {
    if (d == 0) return 0.0;
    const SourceSpan s = sourceSpan(p, g, k);
    return gridError(heights, g.nc, keptRange(s.c0, s.c1, stepOf(d)), keptRange(s.r0, s.r1, stepOf(d)), g.x, g.z);
}

std::vector<double> surfaceErrors(const Patches& p, std::span<const uint8_t> levels, std::span<const float> heights,
                                  size_t stride, SurfaceErrorCache* cache) {
    std::vector<double> out(p.count(), 0.0);
    if (p.cols.size() < 2 || p.rows.size() < 2) return out;
    auto h = [&](uint32_t c, uint32_t r) { return double(heights[stride * (size_t(r) * p.nc + c)]); };
    const uint32_t px = p.patchesX(), pz = p.patchesZ();
    // A patch's surface follows from its level and its four neighbours'.
    auto keyOf = [&](uint32_t i, uint32_t j) {
        auto at = [&](int64_t a, int64_t b) -> uint64_t {
            if (a < 0 || b < 0 || a >= int64_t(px) || b >= int64_t(pz)) return 0xFF;
            return levels[size_t(b) * px + size_t(a)];
        };
        return at(i, j) | at(int64_t(i) - 1, j) << 8 | at(int64_t(i) + 1, j) << 16 | at(i, int64_t(j) - 1) << 24 |
               at(i, int64_t(j) + 1) << 32;
    };
    if (cache && cache->key.size() != p.count()) {
        cache->key.assign(p.count(), ~uint64_t(0));
        cache->error.assign(p.count(), 0.0);
    }
    // What patch (i, j) draws leaves out of the grid.
    auto measure = [&](uint32_t i, uint32_t j, uint32_t k) {
        std::vector<uint32_t> tris;
        if (!appendPatch(tris, p, levels, i, j, nullptr)) return p.error[size_t(k) * p.levels + levels[k]];
        // Zipped: each grid vertex under each triangle against the triangle's plane, in world
        // (x, z).
        return trianglesError(tris, p.nc, 0, h, [&](uint32_t c) { return double(p.x[c]); },
                              [&](uint32_t r) { return double(p.z[r]); });
    };
    tbb::parallel_for(uint32_t(0), p.count(), [&](uint32_t k) {
        const uint32_t i = k % px, j = k / px;
        const uint64_t key = keyOf(i, j);
        if (cache && cache->key[k] == key) {
            out[k] = cache->error[k];
            return;
        }
        out[k] = measure(i, j, k);
        if (cache) cache->key[k] = key, cache->error[k] = out[k];
    });
    return out;
}

void appendSkirt(std::vector<uint32_t>& indices, const SkirtVertices& k, const std::vector<uint32_t>& segments) {
    for (size_t i = 0; i + 1 < segments.size(); i += 2) {
        const uint32_t a = segments[i], b = segments[i + 1];
        const uint32_t ca = a % k.nc, ra = a / k.nc, cb = b % k.nc, rb = b / k.nc;
        uint32_t ta, tb;
        if (ra == rb && ra == 0) ta = k.north[ca], tb = k.north[cb];
        else if (ra == rb) ta = k.south[ca], tb = k.south[cb];
        else if (ca == 0) ta = k.west[ra], tb = k.west[rb];
        else ta = k.east[ra], tb = k.east[rb];
        indices.insert(indices.end(), {a, b, tb, a, tb, ta});
    }
    indices.insert(indices.end(), k.corners.begin(), k.corners.end());
}

std::vector<double> settleRings(const Patches& p, std::vector<uint8_t>& levels, std::span<const float> heights,
                                size_t stride, const glm::vec3& eye, double fovY, double heightPixels, double maxPixels,
                                SurfaceErrorCache* cache) {
    const uint32_t px = p.patchesX(), pz = p.patchesZ();
    for (;;) {
        std::vector<double> error = surfaceErrors(p, levels, heights, stride, cache);
        std::vector<uint8_t> next = levels;
        for (uint32_t k = 0; k < p.count(); ++k) {
            if (error[k] <= p.error[size_t(k) * p.levels + levels[k]]) continue;  // not past its own level
            if (screenPixels(error[k], distanceToBox(eye, p.lo[k], p.hi[k]), fovY, heightPixels) <= maxPixels) continue;
            // The ring strays for a coarser neighbour's edge: that neighbour comes a level finer.
            const uint32_t i = k % px, j = k / px;
            auto finer = [&](int64_t a, int64_t b) {
                if (a < 0 || b < 0 || a >= int64_t(px) || b >= int64_t(pz)) return;
                uint8_t& l = next[size_t(b) * px + size_t(a)];
                if (levels[size_t(b) * px + size_t(a)] > levels[k] && l == levels[size_t(b) * px + size_t(a)]) --l;
            };
            finer(int64_t(i) - 1, j), finer(int64_t(i) + 1, j), finer(i, int64_t(j) - 1), finer(i, int64_t(j) + 1);
        }
        if (next == levels) return error;
        levels = std::move(next);
    }
}

}  // namespace terralux::lod
