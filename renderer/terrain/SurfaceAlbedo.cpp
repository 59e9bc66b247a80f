#include "terrain/SurfaceAlbedo.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>

#include <glm/common.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace terralux {

namespace {
// Every 8-bit code decoded once.
const std::array<float, 256>& srgb8Table() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int v = 0; v < 256; ++v) t[size_t(v)] = srgbToLinear(float(v) / 255.0f);
        return t;
    }();
    return table;
}
uint8_t srgb8ByFormula(float linear) { return uint8_t(std::lround(linearToSrgb(linear) * 255.0f)); }

// thresholds[k - 1]: the least float in [0, 1] that encodes to code k or more. The encoding is
// monotonic in its input, so these 255 values are all of it: found by bisection over the float
// bit patterns (which order the non-negative floats) against the formula itself, so that the
// table gives exactly the formula's codes, not those of an inverse curve rounded differently.
const std::array<float, 255>& srgb8Thresholds() {
    static const std::array<float, 255> table = [] {
        std::array<float, 255> t{};
        for (int k = 1; k < 256; ++k) {
            uint32_t lo = 0, hi = std::bit_cast<uint32_t>(1.0f);  // code(lo) < k <= code(hi)
            while (hi - lo > 1) {
                const uint32_t mid = lo + (hi - lo) / 2;
                (srgb8ByFormula(std::bit_cast<float>(mid)) >= k ? hi : lo) = mid;
            }
            t[size_t(k - 1)] = std::bit_cast<float>(hi);
        }
        return t;
    }();
    return table;
}
}  // namespace

// The formula's code by a search of its thresholds: the same byte without three calls of pow
// per texel (they were a third of loading a 4800 x 4800 terrain).
uint8_t srgb8(float linear) {
    if (!(linear > 0.0f)) return 0;  // NaN and below zero encode as 0, as the clamp makes them
    const auto& t = srgb8Thresholds();
    return uint8_t(std::upper_bound(t.begin(), t.end(), linear) - t.begin());
}

float linearOfSrgb8(uint8_t code) { return srgb8Table()[code]; }

void SurfaceAlbedo::resize(int w, int h) {
    width = w;
    height = h;
    srgb.assign(size_t(std::max(w, 0)) * size_t(std::max(h, 0)) * 3, 0);
}

glm::vec3 SurfaceAlbedo::texel(size_t i) const {
    const auto& t = srgb8Table();
    return {t[srgb[3 * i]], t[srgb[3 * i + 1]], t[srgb[3 * i + 2]]};
}

void SurfaceAlbedo::setTexel(size_t i, glm::vec3 linear) {
    for (int c = 0; c < 3; ++c) srgb[3 * i + size_t(c)] = srgb8(linear[c]);
}

glm::vec3 SurfaceAlbedo::at(const Heightfield& terrain, float x, float z) const {
    if (empty()) return fallback;
    const float spanX = terrain.maxX() - terrain.minX(), spanZ = terrain.maxZ() - terrain.minZ();
    const float fx = width > 1 && spanX > 0.0f
                         ? std::clamp((x - terrain.minX()) / spanX, 0.0f, 1.0f) * float(width - 1)
                         : 0.0f;
    const float fz = height > 1 && spanZ > 0.0f
                         ? std::clamp((z - terrain.minZ()) / spanZ, 0.0f, 1.0f) * float(height - 1)
                         : 0.0f;
    const int ix = std::min(int(fx), std::max(width - 2, 0));
    const int iz = std::min(int(fz), std::max(height - 2, 0));
    const int ix1 = std::min(ix + 1, width - 1), iz1 = std::min(iz + 1, height - 1);
    const float tx = fx - float(ix), tz = fz - float(iz);
    const size_t row0 = size_t(iz) * size_t(width), row1 = size_t(iz1) * size_t(width);
    return (1.0f - tz) * ((1.0f - tx) * texel(row0 + ix) + tx * texel(row0 + ix1)) +
           tz * ((1.0f - tx) * texel(row1 + ix) + tx * texel(row1 + ix1));
}

glm::vec3 SurfaceAlbedo::maximum() const {
    if (empty()) return fallback;
    uint8_t m[3] = {0, 0, 0};
    for (size_t i = 0; i < srgb.size(); ++i) m[i % 3] = std::max(m[i % 3], srgb[i]);
    return {linearOfSrgb8(m[0]), linearOfSrgb8(m[1]), linearOfSrgb8(m[2])};
}

glm::vec3 rampColor(const AlbedoRampSettings& ramp, double elevation, double slopeDeg) {
    const auto& h = ramp.heights;
    const auto& c = ramp.colors;
    glm::vec3 ground = c.empty() ? glm::vec3(0.0f) : c.front();
    if (!h.empty() && c.size() == h.size()) {
        if (elevation >= h.back()) {
            ground = c.back();
        } else if (elevation > h.front()) {
            const size_t k = size_t(std::upper_bound(h.begin(), h.end(), elevation) - h.begin());
            const float t = float((elevation - h[k - 1]) / (h[k] - h[k - 1]));
            ground = glm::mix(c[k - 1], c[k], t);
        }
    }
    // smoothstep(e0, e1, slope) = t²(3 − 2t), t = clamp((slope − e0)/(e1 − e0), 0, 1)
    // (the GLSL definition, GLSL 4.60 specification §8.3).
    const double e0 = ramp.rockSlopeDeg[0], e1 = ramp.rockSlopeDeg[1];
    double t = e1 > e0 ? (slopeDeg - e0) / (e1 - e0) : (slopeDeg >= e0 ? 1.0 : 0.0);
    t = std::clamp(t, 0.0, 1.0);
    const float rock = float(t * t * (3.0 - 2.0 * t));
    return glm::mix(ground, ramp.rockColor, rock);
}

SurfaceAlbedo rampAlbedo(const Heightfield& terrain, const AlbedoRampSettings& ramp,
                         double verticalScale, glm::vec3 fallback) {
    SurfaceAlbedo out;
    out.fallback = fallback;
    const int w = terrain.width(), d = terrain.depth();
    const double shrink = std::min(1.0, double(kMaxSurfaceAlbedoSide) / double(std::max(w, d)));
    out.width = shrink < 1.0 ? std::max(2, int(std::lround(w * shrink))) : w;
    out.height = shrink < 1.0 ? std::max(2, int(std::lround(d * shrink))) : d;
    out.resize(out.width, out.height);
    const double scale = verticalScale > 0.0 ? verticalScale : 1.0;
    // Texel i's centre lies at vertex i (w − 1)/(width − 1): the vertex itself at full size.
    auto vertexOf = [](int i, int texels, int vertices) {
        return texels > 1 ? int(std::lround(double(i) * (vertices - 1) / (texels - 1))) : 0;
    };
    // The slope enters only through the rock smoothstep between rockSlopeDeg[0] and [1]: a normal
    // clearly steeper or flatter than both (by 1e-6 in its cosine, far beyond acos's rounding)
    // gives the same colour for any slope on its side, so acos runs only near the blend.
    const double e0 = ramp.rockSlopeDeg[0], e1 = ramp.rockSlopeDeg[1];
    constexpr double kMargin = 1e-6;
    const double flatAbove = std::cos(std::clamp(e0, 0.0, 180.0) * std::numbers::pi / 180.0) + kMargin;
    const double steepBelow =
        e1 > e0 ? std::cos(std::clamp(e1, 0.0, 180.0) * std::numbers::pi / 180.0) - kMargin : -2.0;
    // Rows are independent: one task per band of rows, the same bytes on any thread count.
    std::vector<int> columnOf(size_t(out.width));
    for (int i = 0; i < out.width; ++i) columnOf[size_t(i)] = vertexOf(i, out.width, w);
    tbb::parallel_for(tbb::blocked_range<int>(0, out.height, 16), [&](const tbb::blocked_range<int>& rows) {
        for (int j = rows.begin(); j < rows.end(); ++j)
            for (int i = 0, r = vertexOf(j, out.height, d); i < out.width; ++i) {
                const int c = columnOf[size_t(i)];
                const double elevation = (double(terrain.at(c, r)) + terrain.geo.height) / scale;
                const double ny = std::clamp(double(terrain.vertexNormal(c, r).y), -1.0, 1.0);
                const double slope = ny > flatAbove     ? e0 - 1.0
                                     : ny < steepBelow ? e1 + 1.0
                                                       : std::acos(ny) * 180.0 / std::numbers::pi;
                out.setTexel(size_t(j) * size_t(out.width) + size_t(i), rampColor(ramp, elevation, slope));
            }
    });
    // Cells the DEM left as nodata: the import's fill is smooth, so their slope and often their
    // height are not the ground's (a filled radar shadow on a rock face turns flat and takes snow).
    // They take the colour of the ground around them instead: filled from the edge of each void
    // inward, a ring at a time, each texel the mean of its already coloured 8 neighbours (a ring is
    // computed from the rings before it only, so the result does not depend on the order).
    const std::vector<uint8_t>& mask = terrain.nodataMask();
    if (mask.empty()) return out;
    const size_t n = out.texels();
    std::vector<uint8_t> coloured(n, 1);
    std::vector<size_t> pending;
    for (int j = 0; j < out.height; ++j)
        for (int i = 0; i < out.width; ++i)
            if (mask[size_t(vertexOf(j, out.height, d)) * size_t(w) + size_t(vertexOf(i, out.width, w))]) {
                coloured[size_t(j) * size_t(out.width) + size_t(i)] = 0;
                pending.push_back(size_t(j) * size_t(out.width) + size_t(i));
            }
    std::vector<std::pair<size_t, glm::vec3>> ring;
    while (!pending.empty()) {
        ring.clear();
        std::vector<size_t> later;
        for (size_t t : pending) {
            const int i = int(t % size_t(out.width)), j = int(t / size_t(out.width));
            glm::vec3 sum(0.0f);
            int count = 0;
            for (int dj = -1; dj <= 1; ++dj)
                for (int di = -1; di <= 1; ++di) {
                    const int x = i + di, y = j + dj;
                    if ((di == 0 && dj == 0) || x < 0 || y < 0 || x >= out.width || y >= out.height) continue;
                    const size_t u = size_t(y) * size_t(out.width) + size_t(x);
                    if (coloured[u]) sum += out.texel(u), ++count;
                }
            if (count > 0) ring.emplace_back(t, sum / float(count));
            else later.push_back(t);
        }
        if (ring.empty()) break;  // a terrain that is all void keeps the ramp's own colours
        for (const auto& [t, c] : ring) {
            out.setTexel(t, c);
            coloured[t] = 1;
        }
        pending = std::move(later);
    }
    return out;
}

// IEC 61966-2-1:1999, §5.2: the piecewise curve with the linear toe below 0.04045.
float srgbToLinear(float v) {
    const double e = std::clamp(double(v), 0.0, 1.0);
    return float(e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4));
}

float linearToSrgb(float v) {
    const double l = std::clamp(double(v), 0.0, 1.0);
    return float(l <= 0.0031308 ? l * 12.92 : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055);
}

}  // namespace terralux
