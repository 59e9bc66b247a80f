#include "terrain/SurfaceMaps.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>

namespace terralux {

namespace {

// The vertex range [first, last] a level-0 texel averages: the vertices nearer its centre than to
// any other texel's, so every vertex counts once.
void texelSpan(int texel, int texels, int vertices, int& first, int& last) {
    if (texels == vertices) {
        first = last = texel;
        return;
    }
    const double step = double(vertices - 1) / double(std::max(texels - 1, 1));
    first = std::max(0, int(std::ceil((texel - 0.5) * step)));
    last = std::min(vertices - 1, int(std::ceil((texel + 0.5) * step)) - 1);
    if (texel == texels - 1) last = vertices - 1;
    last = std::max(last, first);
}

}  // namespace

SurfaceMaps buildSurfaceMaps(const Heightfield& hf, const std::vector<float>& ao, int maxTexels) {
    SurfaceMaps m;
    maxTexels = std::max(maxTexels, 2);
    m.width = std::min(hf.width(), maxTexels);
    m.height = std::min(hf.depth(), maxTexels);
    const bool haveAo = ao.size() == size_t(hf.width()) * size_t(hf.depth());
    const auto& mask = hf.nodataMask();
    const bool haveMask = mask.size() == hf.heights().size();

    std::vector<glm::vec4> level0(size_t(m.width) * size_t(m.height));
    m.filled.assign(level0.size(), 0);
    tbb::parallel_for(0, m.height, [&](int j) {
        int r0, r1;
        texelSpan(j, m.height, hf.depth(), r0, r1);
        for (int i = 0; i < m.width; ++i) {
            int c0, c1;
            texelSpan(i, m.width, hf.width(), c0, c1);
            glm::vec3 n(0.0f);
            double a = 0.0;
            int filled = 0, count = 0;
            for (int r = r0; r <= r1; ++r)
                for (int c = c0; c <= c1; ++c) {
                    const size_t v = size_t(r) * size_t(hf.width()) + size_t(c);
                    n += hf.vertexNormal(c, r);
                    a += haveAo ? ao[v] : 1.0;
                    filled += haveMask && mask[v] ? 1 : 0;
                    ++count;
                }
            const size_t t = size_t(j) * size_t(m.width) + size_t(i);
            level0[t] = glm::vec4(n / float(count), float(a / count));
            m.filled[t] = uint8_t(std::lround(255.0 * filled / count));
        }
    });

    // Mip levels: the box mean of 2×2 texels (the last row or column of an odd size joins the
    // one before it), down to 1×1.
    m.normalAo.push_back(std::move(level0));
    int w = m.width, h = m.height;
    while (w > 1 || h > 1) {
        const int nw = std::max(w / 2, 1), nh = std::max(h / 2, 1);
        const std::vector<glm::vec4>& src = m.normalAo.back();
        std::vector<glm::vec4> dst(size_t(nw) * size_t(nh));
        tbb::parallel_for(0, nh, [&](int j) {
            const int y0 = j * h / nh, y1 = (j + 1) * h / nh;
            for (int i = 0; i < nw; ++i) {
                const int x0 = i * w / nw, x1 = (i + 1) * w / nw;
                glm::vec4 sum(0.0f);
                for (int y = y0; y < y1; ++y)
                    for (int x = x0; x < x1; ++x) sum += src[size_t(y) * size_t(w) + size_t(x)];
                dst[size_t(j) * size_t(nw) + size_t(i)] = sum / float((y1 - y0) * (x1 - x0));
            }
        });
        m.normalAo.push_back(std::move(dst));
        w = nw;
        h = nh;
    }
    return m;
}

float toksvigVariance(float meanLength) {
    const float len = std::clamp(meanLength, 1e-4f, 1.0f);
    return (1.0f - len) / len;
}

float widenedRoughness(float roughness, float variance) {
    const float r2 = roughness * roughness;
    return std::sqrt(std::min(r2 + std::max(variance, 0.0f) * (1.0f - r2), 1.0f));
}

}  // namespace terralux
