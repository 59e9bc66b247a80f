#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "terrain/DerivedCache.h"
#include "terrain/Heightfield.h"

using namespace terralux;

TEST(Heightfield, FixedDiagonalSplitsEachCell) {
    // One cell: h00 = 0, h10 = 0, h01 = 0, h11 = 4. Along the diagonal (0,0)-(1,1) the surface
    // rises linearly; off it, each triangle is planar.
    Heightfield hf(2, 2, 1.0, 1.0, {0.f, 0.f, 0.f, 4.f});
    const float x0 = hf.minX(), z0 = hf.minZ();
    EXPECT_FLOAT_EQ(hf.surfaceHeight(x0 + 0.5f, z0 + 0.5f), 2.0f);  // on the diagonal
    // Triangle A (fx <= fz): h = fx * (h11 - h01) -> at (0.25, 0.75): 1
    EXPECT_FLOAT_EQ(hf.surfaceHeight(x0 + 0.25f, z0 + 0.75f), 1.0f);
    // Triangle B (fx > fz): h = fz * (h11 - h10) -> at (0.75, 0.25): 1
    EXPECT_FLOAT_EQ(hf.surfaceHeight(x0 + 0.75f, z0 + 0.25f), 1.0f);
    // Bilinear interpolation would give 0.75 there: the split is what the mesh draws.
    const glm::vec3 nA = hf.surfaceNormal(x0 + 0.25f, z0 + 0.75f);
    EXPECT_NEAR(nA.x, -4.0f / std::sqrt(17.0f), 1e-6);
    EXPECT_NEAR(nA.z, 0.0f, 1e-6);
}

TEST(Heightfield, SkirtContinuesTheBorder) {
    Heightfield hf(3, 2, 10.0, 10.0, {1.f, 2.f, 3.f, 4.f, 5.f, 6.f});
    EXPECT_FLOAT_EQ(hf.surfaceHeight(hf.maxX() + 1000.0f, hf.minZ()), 3.0f);  // north-east corner
    EXPECT_FLOAT_EQ(hf.surfaceHeight(hf.minX() - 50.0f, hf.maxZ() + 50.0f), 4.0f);
    EXPECT_FLOAT_EQ(hf.surfaceHeight(0.0f, hf.minZ() - 1e6f), 2.0f);  // north edge, middle
}

TEST(Heightfield, FrameAndExtent) {
    Heightfield hf(5, 3, 10.0, 20.0, std::vector<float>(15, 7.f));
    EXPECT_FLOAT_EQ(hf.minX(), -20.f);
    EXPECT_FLOAT_EQ(hf.maxX(), 20.f);
    EXPECT_FLOAT_EQ(hf.minZ(), -20.f);
    EXPECT_FLOAT_EQ(hf.maxZ(), 20.f);
    EXPECT_EQ(hf.vertex(0, 0), glm::vec3(-20.f, 7.f, -20.f));
}

TEST(Heightfield, DegenerateGrids) {
    Heightfield one(1, 1, 1.0, 1.0, {42.f});
    EXPECT_FLOAT_EQ(one.surfaceHeight(5.f, -3.f), 42.f);
    EXPECT_EQ(one.surfaceNormal(0.f, 0.f), glm::vec3(0, 1, 0));
    Heightfield row(3, 1, 1.0, 1.0, {0.f, 2.f, 4.f});
    EXPECT_FLOAT_EQ(row.surfaceHeight(0.5f, 0.f), 3.f);
}

TEST(Heightfield, RejectsBadInput) {
    EXPECT_THROW(Heightfield(0, 1, 1.0, 1.0, {}), std::invalid_argument);
    EXPECT_THROW(Heightfield(1, 1, 0.0, 1.0, {1.f}), std::invalid_argument);
    EXPECT_THROW(Heightfield(2, 1, 1.0, 1.0, {1.f}), std::invalid_argument);
    EXPECT_THROW(Heightfield(1, 1, 1.0, 1.0, {NAN}), std::invalid_argument);
}

// What is derived from a grid alone is kept under its serial (DerivedCache): a copy holds the same
// samples and keeps it; a new grid, a window, a new placement or new nodata marks take a new one,
// so nothing kept for one grid is ever read for another, even one built where it lay in memory.
TEST(Heightfield, ASerialNamesWhatTheGridHolds) {
    Heightfield a(3, 2, 10.0, 10.0, {1.f, 2.f, 3.f, 4.f, 5.f, 6.f});
    EXPECT_EQ(Heightfield().serial(), 0u);
    EXPECT_NE(a.serial(), 0u);
    const Heightfield copy = a;
    EXPECT_EQ(copy.serial(), a.serial());
    const Heightfield same(3, 2, 10.0, 10.0, {1.f, 2.f, 3.f, 4.f, 5.f, 6.f});
    EXPECT_NE(same.serial(), a.serial());  // built again: not known to hold the same
    const Heightfield w = a.window(1, 0, 2, 2);
    EXPECT_NE(w.serial(), a.serial());
    uint64_t before = a.serial();
    a.placeInGrid(5, 4, 1, 1);
    EXPECT_NE(a.serial(), before);
    before = a.serial();
    a.setNodataMask({0, 1, 0, 0, 0, 0});
    EXPECT_NE(a.serial(), before);
    EXPECT_EQ(copy.serial(), Heightfield(copy).serial());
    Heightfield from = copy;
    const Heightfield to = std::move(from);
    EXPECT_EQ(to.serial(), copy.serial());
    EXPECT_EQ(from.serial(), 0u);  // NOLINT(bugprone-use-after-move): what a move leaves
}

// A cache with a byte budget keeps the newest values within it, the newest always, and no more
// than its count; a value it let go is computed again.
TEST(DerivedCache, KeepsTheNewestWithinItsCountAndBytes) {
    DerivedCache<std::string> cache(3, 10, [](const std::string& s) { return s.size(); });
    int computed = 0;
    auto get = [&](const std::string& key, size_t bytes) {
        return *cache.get(7, key, [&] {
            ++computed;
            return std::string(bytes, 'x');
        });
    };
    get("a", 4);
    get("b", 4);
    EXPECT_EQ(cache.size(), 2u);
    EXPECT_EQ(cache.bytes(), 8u);
    get("c", 4);  // 12 bytes: "a", the oldest, goes
    EXPECT_EQ(cache.size(), 2u);
    EXPECT_EQ(cache.bytes(), 8u);
    get("b", 4);
    EXPECT_EQ(computed, 3);  // "b" was kept
    get("a", 4);
    EXPECT_EQ(computed, 4);  // "a" was not
    get("big", 25);          // over the budget alone: kept, alone
    EXPECT_EQ(cache.size(), 1u);
    EXPECT_EQ(cache.bytes(), 25u);
    get("big", 25);
    EXPECT_EQ(computed, 5);
    DerivedCache<std::string> counted(2);  // no budget: its count alone
    for (const char* k : {"a", "b", "c"}) counted.get(7, k, [] { return std::string(100, 'x'); });
    EXPECT_EQ(counted.size(), 2u);
    EXPECT_EQ(counted.get(0, "a", [] { return std::string(); })->size(), 0u);  // serial 0: never kept
    EXPECT_EQ(counted.size(), 2u);
}

TEST(Heightfield, ASampleRangeIsTheRangeOfItsSamples) {
    // 70 x 53: neither side a whole number of blocks, so the cut-short last blocks are read too.
    const int w = 70, d = 53;
    std::vector<float> h(size_t(w) * d);
    uint32_t state = 12345u;
    for (float& v : h) {
        state = state * 1664525u + 1013904223u;
        v = float(state >> 8) / float(1 << 24) * 1000.0f - 300.0f;
    }
    const Heightfield hf(w, d, 1.0, 1.0, h);
    auto brute = [&](int c0, int c1, int r0, int r1) {
        float lo = INFINITY, hi = -INFINITY;
        for (int r = r0; r <= r1; ++r)
            for (int c = c0; c <= c1; ++c) lo = std::min(lo, hf.at(c, r)), hi = std::max(hi, hf.at(c, r));
        return std::pair(lo, hi);
    };
    size_t withBlocks = 0;
    for (int c0 = 0; c0 < w; c0 += 3)
        for (int c1 = c0; c1 < w; c1 += 5)
            for (int r0 = 0; r0 < d; r0 += 4)
                for (int r1 = r0; r1 < d; r1 += 7) {
                    ASSERT_EQ(hf.sampleRange(c0, c1, r0, r1), brute(c0, c1, r0, r1)) << c0 << ".." << c1 << " x " << r0 << ".." << r1;
                    withBlocks += c1 - c0 >= 2 * Heightfield::kRangeBlock && r1 - r0 >= 2 * Heightfield::kRangeBlock;
                }
    // The whole grid and its edges, where the cut-short blocks lie.
    EXPECT_EQ(hf.sampleRange(0, w - 1, 0, d - 1), std::pair(hf.minHeight(), hf.maxHeight()));
    EXPECT_EQ(hf.sampleRange(w - 1, w - 1, 0, d - 1), brute(w - 1, w - 1, 0, d - 1));
    EXPECT_EQ(hf.sampleRange(20, w - 1, 17, d - 1), brute(20, w - 1, 17, d - 1));
    EXPECT_GT(withBlocks, 100u);
}
