#include "terrain/Heightfield.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <glm/geometric.hpp>

namespace terralux {

uint64_t Heightfield::nextSerial() {
    static std::atomic<uint64_t> last{0};
    return ++last;
}

Heightfield::Heightfield(int width, int depth, double cellSizeX, double cellSizeZ,
                         std::vector<float> heights)
    : serial_(nextSerial()), width_(width), depth_(depth), cellSizeX_(cellSizeX), cellSizeZ_(cellSizeZ),
      originCol_(0.5 * (width - 1)), originRow_(0.5 * (depth - 1)), heights_(std::move(heights)) {
    if (width < 1 || depth < 1)
        throw std::invalid_argument("heightfield: size " + std::to_string(width) + "x" +
                                    std::to_string(depth) + " must be at least 1x1");
    if (!(cellSizeX > 0.0) || !(cellSizeZ > 0.0) || !std::isfinite(cellSizeX) ||
        !std::isfinite(cellSizeZ))
        throw std::invalid_argument("heightfield: cell size must be finite and > 0");
    if (heights_.size() != size_t(width) * size_t(depth))
        throw std::invalid_argument("heightfield: " + std::to_string(heights_.size()) +
                                    " heights for a " + std::to_string(width) + "x" +
                                    std::to_string(depth) + " grid");
    minHeight_ = heights_[0];
    maxHeight_ = heights_[0];
    double sum = 0.0;
    for (float h : heights_) {
        if (!std::isfinite(h)) throw std::invalid_argument("heightfield: non-finite height");
        minHeight_ = std::min(minHeight_, h);
        maxHeight_ = std::max(maxHeight_, h);
        sum += h;
    }
    meanHeight_ = float(sum / double(heights_.size()));

    blocksX_ = (width_ + kRangeBlock - 1) / kRangeBlock;
    const int blocksZ = (depth_ + kRangeBlock - 1) / kRangeBlock;
    blockMin_.assign(size_t(blocksX_) * size_t(blocksZ), std::numeric_limits<float>::infinity());
    blockMax_.assign(blockMin_.size(), -std::numeric_limits<float>::infinity());
    for (int row = 0; row < depth_; ++row) {
        float* lo = blockMin_.data() + size_t(row / kRangeBlock) * size_t(blocksX_);
        float* hi = blockMax_.data() + size_t(row / kRangeBlock) * size_t(blocksX_);
        const float* h = heights_.data() + size_t(row) * size_t(width_);
        for (int col = 0; col < width_; ++col) {
            const int b = col / kRangeBlock;
            lo[b] = std::min(lo[b], h[col]);
            hi[b] = std::max(hi[b], h[col]);
        }
    }
}

std::pair<float, float> Heightfield::sampleRange(int col0, int col1, int row0, int row1) const {
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    auto scan = [&](int c0, int c1, int r0, int r1) {
        for (int row = r0; row <= r1; ++row) {
            const float* h = heights_.data() + size_t(row) * size_t(width_);
            for (int col = c0; col <= c1; ++col) {
                lo = std::min(lo, h[col]);
                hi = std::max(hi, h[col]);
            }
        }
    };
    // The blocks wholly inside: from the first block starting at or after the first index to
    // the last ending at or before the last (the grid's last block ends at its edge).
    constexpr int B = kRangeBlock;
    const int blocksZ = (depth_ + B - 1) / B;
    const int bc0 = (col0 + B - 1) / B, bc1 = col1 == width_ - 1 ? blocksX_ - 1 : (col1 + 1) / B - 1;
    const int br0 = (row0 + B - 1) / B, br1 = row1 == depth_ - 1 ? blocksZ - 1 : (row1 + 1) / B - 1;
    if (bc0 > bc1 || br0 > br1) {
        scan(col0, col1, row0, row1);
        return {lo, hi};
    }
    for (int b = br0; b <= br1; ++b)
        for (int a = bc0; a <= bc1; ++a) {
            lo = std::min(lo, blockMin_[size_t(b) * size_t(blocksX_) + size_t(a)]);
            hi = std::max(hi, blockMax_[size_t(b) * size_t(blocksX_) + size_t(a)]);
        }
    const int inCol0 = bc0 * B, inCol1 = std::min((bc1 + 1) * B, width_) - 1;
    const int inRow0 = br0 * B, inRow1 = std::min((br1 + 1) * B, depth_) - 1;
    scan(col0, col1, row0, inRow0 - 1);  // rows above the blocks
    scan(col0, col1, inRow1 + 1, row1);  // rows below
    scan(col0, inCol0 - 1, inRow0, inRow1);  // the blocks' rows, left of them
    scan(inCol1 + 1, col1, inRow0, inRow1);  // and right
    return {lo, hi};
}

float Heightfield::surfaceHeight(float x, float z) const {
    const double gx = std::clamp(colOf(x), 0.0, double(width_ - 1));
    const double gz = std::clamp(rowOf(z), 0.0, double(depth_ - 1));
    const int c = std::min(int(gx), std::max(width_ - 2, 0));
    const int r = std::min(int(gz), std::max(depth_ - 2, 0));
    if (width_ == 1 && depth_ == 1) return at(0, 0);
    if (width_ == 1) {
        const double fz = gz - r;
        return float(at(0, r) + fz * (at(0, r + 1) - at(0, r)));
    }
    if (depth_ == 1) {
        const double fx = gx - c;
        return float(at(c, 0) + fx * (at(c + 1, 0) - at(c, 0)));
    }
    const double fx = gx - c, fz = gz - r;
    const double h00 = at(c, r), h10 = at(c + 1, r), h01 = at(c, r + 1), h11 = at(c + 1, r + 1);
    if (fx <= fz) return float(h00 + fz * (h01 - h00) + fx * (h11 - h01));
    return float(h00 + fx * (h10 - h00) + fz * (h11 - h10));
}

glm::vec3 Heightfield::surfaceNormal(float x, float z) const {
    if (!contains(x, z) || width_ < 2 || depth_ < 2) return {0.0f, 1.0f, 0.0f};
    const double gx = colOf(x);
    const double gz = rowOf(z);
    const int c = std::min(int(gx), width_ - 2);
    const int r = std::min(int(gz), depth_ - 2);
    const double fx = gx - c, fz = gz - r;
    const double h00 = at(c, r), h10 = at(c + 1, r), h01 = at(c, r + 1), h11 = at(c + 1, r + 1);
    double dhdx, dhdz;
    if (fx <= fz) {
        dhdx = (h11 - h01) / cellSizeX_;
        dhdz = (h01 - h00) / cellSizeZ_;
    } else {
        dhdx = (h10 - h00) / cellSizeX_;
        dhdz = (h11 - h10) / cellSizeZ_;
    }
    return glm::normalize(glm::vec3(float(-dhdx), 1.0f, float(-dhdz)));
}

glm::vec3 Heightfield::vertexNormal(int col, int row) const {
    const int c0 = std::max(col - 1, 0), c1 = std::min(col + 1, width_ - 1);
    const int r0 = std::max(row - 1, 0), r1 = std::min(row + 1, depth_ - 1);
    const double dhdx = c1 > c0 ? (at(c1, row) - at(c0, row)) / ((c1 - c0) * cellSizeX_) : 0.0;
    const double dhdz = r1 > r0 ? (at(col, r1) - at(col, r0)) / ((r1 - r0) * cellSizeZ_) : 0.0;
    return glm::normalize(glm::vec3(float(-dhdx), 1.0f, float(-dhdz)));
}

Heightfield Heightfield::window(int col0, int row0, int width, int depth) const {
    if (width < 1 || depth < 1 || col0 < 0 || row0 < 0 || col0 + width > width_ || row0 + depth > depth_)
        throw std::invalid_argument("heightfield: window " + std::to_string(width) + "x" + std::to_string(depth) +
                                    " at (" + std::to_string(col0) + ", " + std::to_string(row0) +
                                    ") must lie inside the " + std::to_string(width_) + "x" +
                                    std::to_string(depth_) + " grid");
    std::vector<float> h(size_t(width) * size_t(depth));
    std::vector<uint8_t> mask(nodataMask_.empty() ? 0 : h.size());
    for (int r = 0; r < depth; ++r) {
        const size_t from = size_t(row0 + r) * size_t(width_) + size_t(col0), to = size_t(r) * size_t(width);
        std::copy_n(heights_.begin() + std::ptrdiff_t(from), width, h.begin() + std::ptrdiff_t(to));
        if (!mask.empty())
            std::copy_n(nodataMask_.begin() + std::ptrdiff_t(from), width, mask.begin() + std::ptrdiff_t(to));
    }
    Heightfield w(width, depth, cellSizeX_, cellSizeZ_, std::move(h));
    // Half-integers: the shifted origin is exact, so xOf gives the parent's coordinates exactly.
    w.originCol_ = originCol_ - col0;
    w.originRow_ = originRow_ - row0;
    if (std::find(mask.begin(), mask.end(), uint8_t(1)) != mask.end()) w.nodataMask_ = std::move(mask);
    w.serial_ = nextSerial();
    w.geo = geo;
    return w;
}

void Heightfield::setNodataMask(std::vector<uint8_t> mask) {
    if (!mask.empty() && mask.size() != heights_.size())
        throw std::invalid_argument("heightfield: nodata mask size does not match the grid");
    nodataMask_ = std::move(mask);
    nodataCount_ = size_t(std::count(nodataMask_.begin(), nodataMask_.end(), uint8_t(1)));
    serial_ = nextSerial();
}

}  // namespace terralux
