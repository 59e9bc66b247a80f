// The terrain mesh's levels of detail (renderer/terrain/MeshLod.h): the vertices each level
// keeps, its triangles, the error bound it carries and the level a camera picks.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include "DemImport.h"
#include "MountainDems.h"
#include "terrain/MeshLod.h"

using namespace terralux;

TEST(MeshLod, ALevelKeepsEveryStepthVertexAndTheLast) {
    EXPECT_EQ(lod::kept(10, 4), (std::vector<uint32_t>{0, 4, 8, 9}));
    EXPECT_EQ(lod::kept(9, 4), (std::vector<uint32_t>{0, 4, 8}));
    EXPECT_EQ(lod::kept(5, 1), (std::vector<uint32_t>{0, 1, 2, 3, 4}));
    EXPECT_EQ(lod::kept(1, 2), (std::vector<uint32_t>{0}));
    EXPECT_TRUE(lod::kept(0, 2).empty());
}

// Every level is a watertight grid: each inner edge is shared by two triangles wound opposite
// ways, each border edge belongs to one, and the triangles cover the grid's rectangle once.
TEST(MeshLod, EveryLevelIsAWatertightGridOverTheSameVertices) {
    const uint32_t nc = 11, nr = 7;
    for (uint32_t step : {1u, 2u, 4u}) {
        const std::vector<uint32_t> kc = lod::kept(nc, step), kr = lod::kept(nr, step);
        std::vector<uint32_t> idx;
        lod::appendTriangles(idx, nc, kc, kr);
        ASSERT_EQ(idx.size(), (kc.size() - 1) * (kr.size() - 1) * 6);
        std::map<std::pair<uint32_t, uint32_t>, int> directed;
        double area = 0.0;
        for (size_t t = 0; t < idx.size(); t += 3) {
            for (int e = 0; e < 3; ++e) ++directed[{idx[t + e], idx[t + (e + 1) % 3]}];
            // Signed area in (column, row) space: counter-clockwise from above (y up, rows
            // along +z) is clockwise in (c, r), so negative.
            auto cr = [&](uint32_t v) { return std::array<double, 2>{double(v % nc), double(v / nc)}; };
            const auto a = cr(idx[t]), b = cr(idx[t + 1]), c = cr(idx[t + 2]);
            const double signedArea = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]));
            EXPECT_LT(signedArea, 0.0);
            area -= signedArea;
        }
        EXPECT_DOUBLE_EQ(area, double((nc - 1) * (nr - 1))) << "step " << step;
        size_t border = 0;
        for (const auto& [edge, n] : directed) {
            EXPECT_EQ(n, 1);
            if (!directed.count({edge.second, edge.first})) ++border;
        }
        EXPECT_EQ(border, 2 * (kc.size() - 1) + 2 * (kr.size() - 1)) << "step " << step;
    }
}

TEST(MeshLod, APlaneLosesNothingAtAnyLevel) {
    const uint32_t nc = 9, nr = 6;
    std::vector<float> h(nc * nr);
    for (uint32_t r = 0; r < nr; ++r)
        for (uint32_t c = 0; c < nc; ++c) h[r * nc + c] = 3.0f * float(c) - 2.0f * float(r) + 100.0f;
    for (uint32_t step : {1u, 2u, 4u, 8u})
        EXPECT_NEAR(lod::gridError(h, nc, lod::kept(nc, step), lod::kept(nr, step)), 0.0, 1e-9) << step;
}

// The coarse cell splits along (c, r)-(c+1, r+1) like the mesh and the tracer: a ridge along
// that diagonal is kept whole, and one along the other diagonal is lost.
TEST(MeshLod, TheErrorFollowsTheMeshsDiagonal) {
    // 3 x 3 heights over one coarse cell, a ridge of 6 m along one diagonal, falling linearly to
    // 0 at the other two corners (3 m at the edges' midpoints). Row-major, (c, r) at r * 3 + c.
    const std::vector<float> ridge{6, 3, 0,  //
                                   3, 6, 3,  //
                                   0, 3, 6};
    const std::vector<float> crossRidge{0, 3, 6,  //
                                        3, 6, 3,  //
                                        6, 3, 0};
    const std::vector<uint32_t> k = lod::kept(3, 2);
    EXPECT_DOUBLE_EQ(lod::gridError(ridge, 3, k, k), 0.0);
    // Across the split, the centre falls to the mean of (0, 0) and (2, 2): 0, not 6.
    EXPECT_DOUBLE_EQ(lod::gridError(crossRidge, 3, k, k), 6.0);
    // A peak at one inner vertex is lost whole.
    std::vector<float> peak(25, 0.0f);
    peak[2 * 5 + 1] = 4.5f;
    EXPECT_DOUBLE_EQ(lod::gridError(peak, 5, lod::kept(5, 2), lod::kept(5, 2)), 4.5);
    EXPECT_DOUBLE_EQ(lod::gridError(peak, 5, lod::kept(5, 1), lod::kept(5, 1)), 0.0);
}

TEST(MeshLod, ScreenErrorAndDistance) {
    const double fov = std::numbers::pi / 2.0;  // 2 tan(fov / 2) = 2
    EXPECT_NEAR(lod::screenPixels(1.0, 1000.0, fov, 1000.0), 0.5, 1e-12);
    EXPECT_EQ(lod::screenPixels(0.0, 0.0, fov, 1000.0), 0.0);
    EXPECT_TRUE(std::isinf(lod::screenPixels(0.5, 0.0, fov, 1000.0)));
    EXPECT_DOUBLE_EQ(lod::distanceToBox({0, 0, 0}, {-1, -1, -1}, {1, 1, 1}), 0.0);
    EXPECT_DOUBLE_EQ(lod::distanceToBox({4, 5, 0}, {-1, -1, -1}, {1, 1, 1}), 5.0);
}

namespace {

// A rough grid (a slope and up to 1 m of noise from a hash) of nc x nr vertices, 10 m apart, in patches of `cells`.
struct Terrain {
    uint32_t nc, nr;
    std::vector<float> h, x, z;
    lod::Patches patches;
    Terrain(uint32_t nc_, uint32_t nr_, uint32_t cells) : nc(nc_), nr(nr_), h(size_t(nc_) * nr_), x(nc_), z(nr_) {
        for (uint32_t r = 0; r < nr; ++r)
            for (uint32_t c = 0; c < nc; ++c) {
                uint32_t k = (r * 73856093u) ^ (c * 19349663u);
                k = (k ^ (k >> 13)) * 0x5bd1e995u;
                h[size_t(r) * nc + c] = float(k % 1000u) * 0.001f + 0.5f * float(c);
            }
        for (uint32_t c = 0; c < nc; ++c) x[c] = 10.0f * float(c);
        for (uint32_t r = 0; r < nr; ++r) z[r] = 10.0f * float(r);
        patches = lod::buildPatches(h, nc, nr, x, z, cells);
    }
};

// The directed edges of a triangle list: each inner edge must appear once each way, each border
// edge once; returns false (with a message) otherwise. Also checks every triangle is wound
// counter-clockwise from above and that the triangles cover the grid's area exactly.
::testing::AssertionResult watertight(const std::vector<uint32_t>& idx, uint32_t nc, uint32_t nr) {
    std::map<std::pair<uint32_t, uint32_t>, int> directed;
    double area = 0.0;
    for (size_t t = 0; t < idx.size(); t += 3) {
        auto cr = [&](uint32_t v) { return std::array<double, 2>{double(v % nc), double(v / nc)}; };
        const auto a = cr(idx[t]), b = cr(idx[t + 1]), c = cr(idx[t + 2]);
        const double signedArea = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]));
        if (!(signedArea < 0.0)) return ::testing::AssertionFailure() << "triangle " << t / 3 << " wound " << signedArea;
        area -= signedArea;
        for (int e = 0; e < 3; ++e)
            if (++directed[{idx[t + e], idx[t + (e + 1) % 3]}] > 1)
                return ::testing::AssertionFailure() << "edge " << idx[t + e] << "-" << idx[t + (e + 1) % 3] << " twice";
    }
    for (const auto& [edge, n] : directed) {
        if (directed.count({edge.second, edge.first})) continue;
        // A border edge: both ends on the same border line.
        const uint32_t ca = edge.first % nc, ra = edge.first / nc, cb = edge.second % nc, rb = edge.second / nc;
        const bool border = (ra == rb && (ra == 0 || ra == nr - 1)) || (ca == cb && (ca == 0 || ca == nc - 1));
        if (!border) return ::testing::AssertionFailure() << "crack at edge (" << ca << "," << ra << ")-(" << cb << "," << rb << ")";
    }
    if (std::abs(area - double(nc - 1) * double(nr - 1)) > 1e-6)
        return ::testing::AssertionFailure() << "area " << area << " of " << double(nc - 1) * double(nr - 1);
    return ::testing::AssertionSuccess();
}

}  // namespace

// No cracks whatever the levels: every patch at a random level of its own, neighbours far apart,
// over grids whose patches do not divide them evenly.
TEST(MeshLod, PatchesAtAnyLevelsMeetWithoutCracks) {
    for (const auto& [nc, nr] : {std::pair<uint32_t, uint32_t>{65, 65}, {97, 40}, {130, 75}}) {
        const Terrain t(nc, nr, 16);
        ASSERT_GE(t.patches.count(), 4u);
        EXPECT_GT(t.patches.levels, 3u);
        uint32_t seed = 12345;
        for (int trial = 0; trial < 30; ++trial) {
            std::vector<uint8_t> levels(t.patches.count());
            for (size_t k = 0; k < levels.size(); ++k) {
                seed = seed * 1664525u + 1013904223u;
                levels[k] = uint8_t((seed >> 16) % (t.patches.coarsest[k] + 1u));
            }
            std::vector<uint32_t> idx, border;
            lod::appendPatchTriangles(idx, t.patches, levels, &border);
            ASSERT_TRUE(watertight(idx, nc, nr)) << nc << "x" << nr << " trial " << trial;
            // The border segments run the whole border once.
            double length = 0.0;
            for (size_t i = 0; i + 1 < border.size(); i += 2) {
                const double dc = double(border[i] % nc) - double(border[i + 1] % nc);
                const double dr = double(border[i] / nc) - double(border[i + 1] / nc);
                length += std::abs(dc) + std::abs(dr);
            }
            EXPECT_DOUBLE_EQ(length, 2.0 * (nc - 1) + 2.0 * (nr - 1));
        }
    }
}

// Source resolution under a decimated grid: a source grid drawn from every s-th vertex (s = 3,
// whose detail steps 1 and 2 do not divide it, and 4), patches at random levels, and a random
// choice of patches drawn from the source grid at random detail levels. The drawn patches'
// triangles and the detail patches', each in the source grid's vertices, are one watertight mesh
// of the whole source rectangle: a detail patch meets a drawn neighbour at that neighbour's
// vertices and another detail patch at the coarser of their steps.
TEST(MeshLod, DetailPatchesMeetTheDrawnGridAndEachOtherWithoutCracks) {
    for (const uint32_t stride : {3u, 4u}) {
        const Terrain src(97, 61, 8);
        lod::SourceGrid g;
        g.nc = src.nc;
        g.nr = src.nr;
        g.col = lod::kept(src.nc, stride);
        g.row = lod::kept(src.nr, stride);
        g.x = src.x;
        g.z = src.z;
        const uint32_t nc = uint32_t(g.col.size()), nr = uint32_t(g.row.size());
        std::vector<float> drawn, cx, rz;
        for (uint32_t r : g.row)
            for (uint32_t c : g.col) drawn.push_back(src.h[size_t(r) * src.nc + c]);
        for (uint32_t c : g.col) cx.push_back(src.x[c]);
        for (uint32_t r : g.row) rz.push_back(src.z[r]);
        const lod::Patches p = lod::buildPatches(drawn, nc, nr, cx, rz, 4);
        ASSERT_GE(p.count(), 12u);
        uint32_t seed = 777;
        auto next = [&] { return seed = seed * 1664525u + 1013904223u, seed >> 16; };
        size_t detailed = 0, zipped = 0;
        double detailBorder = 0.0;  // the detail skirts' length, in source cells
        for (int trial = 0; trial < 40; ++trial) {
            std::vector<uint8_t> levels(p.count());
            std::vector<int8_t> detail(p.count(), -1);
            for (uint32_t k = 0; k < p.count(); ++k) {
                levels[k] = uint8_t(next() % (p.coarsest[k] + 1u));
                if (levels[k] == 0 && next() % 3 != 0) detail[k] = int8_t(next() % 2), ++detailed;
            }
            std::vector<uint32_t> main, border;
            lod::appendPatchTriangles(main, p, levels, &border, detail);
            // In the source grid's vertices.
            std::vector<uint32_t> all;
            for (uint32_t v : main) all.push_back(g.row[v / nc] * g.nc + g.col[v % nc]);
            for (uint32_t k = 0; k < p.count(); ++k) {
                if (detail[k] < 0) continue;
                const lod::SourceSpan sp = lod::sourceSpan(p, g, k);
                std::vector<uint32_t> tris;
                lod::appendDetailPatch(tris, p, g, levels, detail, k, 1000);
                // Its vertices: its level's grid and its edges, ascending, counted as listed.
                const std::vector<uint32_t> held = lod::detailVertices(p, g, k, uint8_t(detail[k]));
                ASSERT_EQ(held.size(), lod::detailVertexCount(p, g, k, uint8_t(detail[k])));
                ASSERT_TRUE(std::is_sorted(held.begin(), held.end()));
                for (uint32_t v : tris) {
                    ASSERT_LT(v - 1000, held.size());
                    all.push_back((sp.r0 + held[v - 1000] / sp.nc()) * g.nc + sp.c0 + held[v - 1000] % sp.nc());
                }
                // Its skirt hangs from exactly its edges on the DEM's border: each segment's top
                // edge is one of its triangles' border edges, and every such edge has one; its
                // twins are the ones detailSkirtTwins lists, pushed out across that border.
                std::set<std::pair<uint32_t, uint32_t>> edges, hung;
                for (size_t t = 0; t < tris.size(); t += 3)
                    for (int e = 0; e < 3; ++e) {
                        const uint32_t a = tris[t + e] - 1000, b = tris[t + (e + 1) % 3] - 1000;
                        const uint32_t ca = sp.c0 + held[a] % sp.nc(), ra = sp.r0 + held[a] / sp.nc();
                        const uint32_t cb = sp.c0 + held[b] % sp.nc(), rb = sp.r0 + held[b] / sp.nc();
                        if ((ra == rb && (ra == 0 || ra == g.nr - 1)) || (ca == cb && (ca == 0 || ca == g.nc - 1)))
                            edges.insert({std::min(a, b), std::max(a, b)});
                    }
                std::vector<uint32_t> skirt;
                lod::appendDetailSkirt(skirt, p, g, detail, k, 1000);
                const std::vector<lod::DetailTwin> twins = lod::detailSkirtTwins(p, g, k, uint8_t(detail[k]));
                ASSERT_EQ(skirt.size() % 6, 0u);
                for (size_t t = 0; t < skirt.size(); t += 6) {
                    const uint32_t a = skirt[t] - 1000, b = skirt[t + 1] - 1000;
                    ASSERT_LT(a, held.size());
                    ASSERT_LT(b, held.size());
                    hung.insert({std::min(a, b), std::max(a, b)});
                    detailBorder += std::abs(double(held[a] % sp.nc()) - double(held[b] % sp.nc())) +
                                    std::abs(double(held[a] / sp.nc()) - double(held[b] / sp.nc()));
                    for (const uint32_t tw : {skirt[t + 2] - 1000, skirt[t + 5] - 1000}) {
                        ASSERT_GE(tw, held.size());
                        ASSERT_LT(tw - held.size(), twins.size());
                    }
                    const lod::DetailTwin& ta = twins[skirt[t + 5] - 1000 - held.size()];
                    EXPECT_EQ(ta.c, sp.c0 + held[a] % sp.nc());
                    EXPECT_EQ(ta.r, sp.r0 + held[a] / sp.nc());
                    EXPECT_TRUE((ta.dx != 0 && (ta.c == 0 || ta.c == g.nc - 1)) || (ta.dz != 0 && (ta.r == 0 || ta.r == g.nr - 1)));
                }
                EXPECT_EQ(hung, edges) << "patch " << k;
                // A ring zipped to a coarser side draws a surface the level alone does not.
                const double e = lod::detailSurfaceError(p, g, levels, detail, k, src.h);
                if (std::abs(e - lod::detailLevelError(p, g, k, uint8_t(detail[k]), src.h)) > 1e-9) ++zipped;
            }
            ASSERT_TRUE(watertight(all, g.nc, g.nr)) << "stride " << stride << " trial " << trial;
            // The drawn skirt's segments and the detail skirts run the whole border once, in
            // source cells.
            double length = detailBorder;
            for (size_t i = 0; i + 1 < border.size(); i += 2) {
                const uint32_t a = border[i], b = border[i + 1];
                length += std::abs(double(g.col[a % nc]) - double(g.col[b % nc])) +
                          std::abs(double(g.row[a / nc]) - double(g.row[b / nc]));
            }
            EXPECT_DOUBLE_EQ(length, 2.0 * (g.nc - 1) + 2.0 * (g.nr - 1)) << "stride " << stride << " trial " << trial;
            detailBorder = 0.0;
        }
        EXPECT_GT(detailed, 100u);
        EXPECT_GT(zipped, 10u);
    }
}

// Detail patches at detail level 0 everywhere are the source grid itself: no error. One alone
// among drawn patches zips its rings to their vertices, and its coarser detail levels leave out
// what their grid leaves out.
TEST(MeshLod, ADetailPatchAtLevelZeroIsTheSourceGrid) {
    const Terrain src(97, 97, 8);
    lod::SourceGrid g;
    g.nc = g.nr = src.nc;
    g.col = g.row = lod::kept(src.nc, 4);
    g.x = src.x;
    g.z = src.z;
    const uint32_t n = uint32_t(g.col.size());
    std::vector<float> drawn, cx;
    for (uint32_t r : g.row)
        for (uint32_t c : g.col) drawn.push_back(src.h[size_t(r) * src.nc + c]);
    for (uint32_t c : g.col) cx.push_back(src.x[c]);
    const lod::Patches p = lod::buildPatches(drawn, n, n, cx, cx, 4);
    const std::vector<uint8_t> levels(p.count(), 0);
    const std::vector<int8_t> detail(p.count(), 0);
    for (uint32_t k = 0; k < p.count(); ++k) {
        EXPECT_EQ(lod::detailLevelError(p, g, k, 0, src.h), 0.0);
        // Every side a detail patch at level 0 or the border (drawn at the patch's own step).
        EXPECT_EQ(lod::detailSurfaceError(p, g, levels, detail, k, src.h), 0.0) << k;
        // With a drawn side its ring is zipped to that side's vertices: what they leave out shows.
        std::vector<int8_t> alone(p.count(), -1);
        alone[k] = 0;
        EXPECT_GT(lod::detailSurfaceError(p, g, levels, alone, k, src.h), 0.0) << k;
        EXPECT_GT(lod::detailLevelError(p, g, k, 1, src.h), 0.0);
    }
}

TEST(MeshLod, PastTheBudgetTheDetailGoesWhereItLowersTheLargestError) {
    // Random candidates (errors along the states not always falling), against every assignment
    // within the budget: the largest error on screen is the least any assignment reaches.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> px(0.2, 40.0);
    const double maxPixels = 1.0;
    size_t bound = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        std::vector<lod::DetailCandidate> cs(1 + rng() % 5);
        size_t need = 0;
        for (lod::DetailCandidate& c : cs) {
            const size_t states = 2 + rng() % 3;
            size_t v = 0;
            for (size_t s = 0; s < states; ++s) {
                c.pixels.push_back(s + 1 == states ? 0.0 : px(rng));
                c.vertices.push_back(v);
                v += 1 + rng() % 50;
            }
            c.target = states - 1;
            for (size_t s = states - 1; s-- > 1 && c.pixels[s] <= maxPixels;) c.target = s;
            need += c.vertices[c.target];
        }
        const size_t budget = rng() % (need + 20);
        const std::vector<size_t> got = lod::allocateDetail(cs, budget, maxPixels);
        ASSERT_EQ(got.size(), cs.size());
        size_t used = 0;
        double largest = 0.0;
        for (size_t m = 0; m < cs.size(); ++m) {
            used += cs[m].vertices[got[m]];
            largest = std::max(largest, cs[m].pixels[got[m]]);
        }
        ASSERT_LE(used, budget) << "trial " << trial;
        if (need <= budget) {
            for (size_t m = 0; m < cs.size(); ++m) EXPECT_EQ(got[m], cs[m].target) << "trial " << trial;
            continue;
        }
        ++bound;
        // Every assignment within the budget, by brute force.
        double best = std::numeric_limits<double>::infinity();
        std::vector<size_t> a(cs.size(), 0);
        for (;;) {
            size_t v = 0;
            double worst = 0.0;
            for (size_t m = 0; m < cs.size(); ++m) v += cs[m].vertices[a[m]], worst = std::max(worst, cs[m].pixels[a[m]]);
            if (v <= budget) best = std::min(best, worst);
            size_t m = 0;
            while (m < cs.size() && ++a[m] == cs[m].pixels.size()) a[m++] = 0;
            if (m == cs.size()) break;
        }
        EXPECT_EQ(std::max(largest, maxPixels), std::max(best, maxPixels)) << "trial " << trial;
        // And no budget is left that would bring a candidate still past the pixel nearer.
        for (size_t m = 0; m < cs.size(); ++m) {
            if (cs[m].pixels[got[m]] <= maxPixels) continue;
            for (size_t s = got[m] + 1; s < cs[m].pixels.size(); ++s)
                if (cs[m].pixels[s] < cs[m].pixels[got[m]]) {
                    EXPECT_GT(cs[m].vertices[s] - cs[m].vertices[got[m]], budget - used) << "trial " << trial;
                    break;
                }
        }
    }
    EXPECT_GT(bound, 1000u);
}

// At level 0 everywhere the patches draw exactly the whole grid's triangles (the bake's surface).
TEST(MeshLod, LevelZeroEverywhereIsTheWholeGrid) {
    const Terrain t(70, 45, 16);
    std::vector<uint32_t> idx, whole;
    lod::appendPatchTriangles(idx, t.patches, std::vector<uint8_t>(t.patches.count(), 0));
    lod::appendTriangles(whole, t.nc, lod::kept(t.nc, 1), lod::kept(t.nr, 1));
    auto triangles = [](const std::vector<uint32_t>& v) {
        std::vector<std::array<uint32_t, 3>> out;
        for (size_t i = 0; i < v.size(); i += 3) {
            std::array<uint32_t, 3> tri{v[i], v[i + 1], v[i + 2]};
            std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());
            out.push_back(tri);
        }
        std::sort(out.begin(), out.end());
        return out;
    };
    EXPECT_EQ(triangles(idx), triangles(whole));
}

// A patch's error at each level is its own grid's against the heights (0 at level 0); the
// camera picks, per patch, the coarsest level within the pixel, coarser far away than near.
TEST(MeshLod, EachPatchTakesTheCoarsestLevelWithinAPixel) {
    const Terrain t(129, 129, 16);
    const lod::Patches& p = t.patches;
    ASSERT_EQ(p.count(), 64u);
    for (uint32_t k = 0; k < p.count(); ++k) {
        EXPECT_EQ(p.error[size_t(k) * p.levels], 0.0);
        for (uint32_t l = 1; l <= p.coarsest[k]; ++l) EXPECT_GT(p.error[size_t(k) * p.levels + l], 0.0);
    }
    const double fov = std::numbers::pi / 3.0;
    // Standing over one corner, 100 m up: that patch is under 100 m away, the far corner's 1.7 km.
    const glm::vec3 eye(0.0f, 100.0f, 0.0f);
    const std::vector<uint8_t> levels = lod::chooseLevels(p, eye, fov, 1080.0, 1.0);
    EXPECT_EQ(levels.front(), 0);
    EXPECT_GT(levels.back(), levels.front());
    for (uint32_t k = 0; k < p.count(); ++k) {
        const double d = lod::distanceToBox(eye, p.lo[k], p.hi[k]);
        const double chosen = lod::screenPixels(p.error[size_t(k) * p.levels + levels[k]], d, fov, 1080.0);
        if (levels[k] > 0) {
            EXPECT_LE(chosen, 1.0);
        }
        if (levels[k] < p.coarsest[k]) {
            EXPECT_GT(lod::screenPixels(p.error[size_t(k) * p.levels + levels[k] + 1u], d, fov, 1080.0), 1.0);
        }
    }
    // Far away, every patch draws its coarsest.
    const std::vector<uint8_t> far = lod::chooseLevels(p, glm::vec3(0.0f, 1e7f, 0.0f), fov, 1080.0, 1.0);
    for (uint32_t k = 0; k < p.count(); ++k) EXPECT_EQ(far[k], p.coarsest[k]);
}

// What the printed figure claims on real mountains: from cameras near the ground and far above,
// every vertex of a committed mountain crop lies within the reported pixels of the surface the
// levels draw, seen from that vertex's own distance, zipped rings included (there a finer
// patch's ring takes its coarser neighbour's edge, a surface neither level has). The vertices
// are found under the whole mesh's triangles, not patch by patch as surfaceErrors finds them.
TEST(MeshLod, EveryVertexOfAMountainIsWithinTheReportedPixels) {
    const double fov = 45.0 * std::numbers::pi / 180.0, rows = 1080.0;
    size_t ringsPast = 0, madeFiner = 0;
    // The committed crops in 16-cell patches, and the whole N42E001 tile in the renderer's 32 when
    // the shared data is there.
    for (const test::MountainDem& mountain : test::mountainDems()) {
        const bool shared = mountain.shared;
        const std::string name = mountain.file.filename().string();
        const DemImportResult dem = importDem(mountain.file.string());
        const Heightfield& hf = dem.heightfield;
        // The whole grid, and every third row and column as the renderer draws a DEM past its
        // vertex budget (the last step shorter where the side is not 3k + 1).
        for (const uint32_t stride : {1u, 3u}) {
        const std::vector<uint32_t> keptCols = lod::kept(uint32_t(hf.width()), stride),
                                    keptRows = lod::kept(uint32_t(hf.depth()), stride);
        const uint32_t nc = uint32_t(keptCols.size()), nr = uint32_t(keptRows.size());
        std::vector<float> heights(size_t(nc) * nr), x(nc), z(nr);
        for (uint32_t r = 0; r < nr; ++r)
            for (uint32_t c = 0; c < nc; ++c) heights[size_t(r) * nc + c] = hf.vertex(int(keptCols[c]), int(keptRows[r])).y;
        for (uint32_t c = 0; c < nc; ++c) x[c] = hf.vertex(int(keptCols[c]), 0).x;
        for (uint32_t r = 0; r < nr; ++r) z[r] = hf.vertex(0, int(keptRows[r])).z;
        const lod::Patches p = lod::buildPatches(heights, nc, nr, x, z, shared ? 32 : 16);
        const float top = *std::max_element(heights.begin(), heights.end());
        const glm::vec3 lo(x.front(), 0.0f, z.front()), hi(x.back(), top, z.back());
        const glm::vec3 centre = 0.5f * (lo + hi);
        const float side = std::max(hi.x - lo.x, hi.z - lo.z);
        // Near the ground at a corner and at the centre, over a ridge, and far above.
        const glm::vec3 eyes[] = {glm::vec3(lo.x, heights.front() + 20.0f, lo.z),
                                  glm::vec3(centre.x, heights[size_t(nr / 2) * nc + nc / 2] + 30.0f, centre.z),
                                  glm::vec3(hi.x, top + 200.0f, centre.z),
                                  glm::vec3(centre.x, top + 1.5f * side, centre.z + side)};
        lod::SurfaceErrorCache cache;  // across cameras and pixels, as the renderer keeps it
        for (const glm::vec3& eye : eyes)
          for (const double allowed : {1.0, 4.0, 16.0}) {
            std::vector<uint8_t> levels = lod::chooseLevels(p, eye, fov, rows, allowed);
            const std::vector<uint8_t> chosen = levels;
            const std::vector<double> settled = lod::settleRings(p, levels, heights, 1, eye, fov, rows, allowed, &cache);
            std::vector<uint32_t> tris;
            lod::appendPatchTriangles(tris, p, levels);
            // Every vertex under every triangle: its distance from the triangle's plane in y.
            std::vector<double> deviation(heights.size(), 0.0);
            for (size_t t = 0; t + 2 < tris.size(); t += 3) {
                glm::dvec3 v[3];
                uint32_t c[3], r[3];
                for (int k = 0; k < 3; ++k) {
                    c[k] = tris[t + k] % nc, r[k] = tris[t + k] / nc;
                    v[k] = glm::dvec3(x[c[k]], heights[tris[t + k]], z[r[k]]);
                }
                const glm::dvec3 n = glm::cross(v[1] - v[0], v[2] - v[0]);
                ASSERT_NE(n.y, 0.0);
                for (uint32_t rr = std::min({r[0], r[1], r[2]}); rr <= std::max({r[0], r[1], r[2]}); ++rr)
                    for (uint32_t cc = std::min({c[0], c[1], c[2]}); cc <= std::max({c[0], c[1], c[2]}); ++cc) {
                        const glm::dvec2 q(x[cc], z[rr]);
                        auto side2 = [&](int a, int b) {
                            return (v[b].x - v[a].x) * (q.y - v[a].z) - (v[b].z - v[a].z) * (q.x - v[a].x);
                        };
                        const double s0 = side2(0, 1), s1 = side2(1, 2), s2 = side2(2, 0);
                        const double eps = 1e-9 * std::abs(n.y);  // twice the triangle's area in (x, z)
                        if (!((s0 >= -eps && s1 >= -eps && s2 >= -eps) || (s0 <= eps && s1 <= eps && s2 <= eps)))
                            continue;
                        // The plane through the triangle at (x, z).
                        const double y = v[0].y - (n.x * (q.x - v[0].x) + n.z * (q.y - v[0].z)) / n.y;
                        const size_t i = size_t(rr) * nc + cc;
                        deviation[i] = std::max(deviation[i], std::abs(double(heights[i]) - y));
                    }
            }
            const std::vector<double> reported = lod::surfaceErrors(p, levels, heights);
            EXPECT_EQ(settled, reported);
            size_t finer = 0;
            for (size_t k = 0; k < levels.size(); ++k) {
                EXPECT_LE(levels[k], chosen[k]);
                finer += levels[k] < chosen[k];
            }
            double worstReported = 0.0, worstMeasured = 0.0;
            size_t zipped = 0;
            for (uint32_t k = 0; k < p.count(); ++k) {
                const uint32_t i = k % p.patchesX(), j = k / p.patchesX();
                double measured = 0.0;
                for (uint32_t r = p.rows[j]; r <= p.rows[j + 1]; ++r)
                    for (uint32_t c = p.cols[i]; c <= p.cols[i + 1]; ++c) {
                        const size_t v = size_t(r) * nc + c;
                        measured = std::max(measured, deviation[v]);
                        const double d = glm::length(glm::dvec3(eye) - glm::dvec3(x[c], heights[v], z[r]));
                        worstMeasured = std::max(worstMeasured, lod::screenPixels(deviation[v], d, fov, rows));
                    }
                // surfaceErrors is exact, up to the float coordinates (the level's error is taken
                // in grid steps, the brute force in metres): the patch's own vertices under its own
                // triangles (a vertex on a shared edge lies on the edge, which both draw alike).
                EXPECT_NEAR(reported[k], measured, 1e-3 + 1e-4 * measured) << name << " patch " << k;
                if (reported[k] > p.error[size_t(k) * p.levels + levels[k]] + 1e-9) ++zipped;
                worstReported = std::max(worstReported,
                                         lod::screenPixels(reported[k], lod::distanceToBox(eye, p.lo[k], p.hi[k]), fov, rows));
            }
            std::printf("%s stride %u eye (%.0f, %.0f, %.0f) at %.0f px: measured %.3f px, reported %.3f px, %zu rings above their level, %zu patches finer\n",
                        name.c_str(), stride, eye.x, eye.y, eye.z, allowed, worstMeasured, worstReported, zipped, finer);
            EXPECT_LE(worstMeasured, worstReported + 1e-9) << name;
            EXPECT_LE(worstReported, allowed) << name;
            ringsPast += zipped;
            madeFiner += finer;
        }
        }
    }
    // The crops alone have rings past their level that had to be made finer.
    EXPECT_GT(ringsPast, 0u);
    EXPECT_GT(madeFiner, 0u);
}
