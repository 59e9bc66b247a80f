#pragma once
// Golden-image comparison for the render tests: mean absolute difference and SSIM on luminance
// (Wang et al. 2004, 8x8 windows, C1 = (0.01)^2, C2 = (0.03)^2 for [0, 1] data), plus a diff
// image and where the largest difference is, so a failure says how much and where.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace terralux::test {

struct ImageDiff {
    double meanAbs = 0;      // over RGB, in [0, 1]
    double maxAbs = 0;
    uint32_t maxX = 0, maxY = 0;
    double ssim = 1;
    std::vector<float> diff;  // RGBA, |a - b| x 4 for visibility
};

inline double luma(const std::vector<float>& img, size_t i) {
    return 0.2126 * img[i * 4] + 0.7152 * img[i * 4 + 1] + 0.0722 * img[i * 4 + 2];
}

inline ImageDiff compareImages(const std::vector<float>& a, const std::vector<float>& b,
                               uint32_t w, uint32_t h) {
    ImageDiff d;
    d.diff.assign(size_t(w) * h * 4, 1.0f);
    double sum = 0;
    for (size_t i = 0; i < size_t(w) * h; ++i)
        for (int c = 0; c < 3; ++c) {
            const double e = std::abs(double(a[i * 4 + size_t(c)]) - double(b[i * 4 + size_t(c)]));
            sum += e;
            d.diff[i * 4 + size_t(c)] = float(std::min(1.0, 4.0 * e));
            if (e > d.maxAbs) {
                d.maxAbs = e;
                d.maxX = uint32_t(i % w);
                d.maxY = uint32_t(i / w);
            }
        }
    d.meanAbs = sum / (3.0 * double(w) * h);
    const double c1 = 0.0001, c2 = 0.0009;
    double ssimSum = 0;
    int windows = 0;
    for (uint32_t y = 0; y + 8 <= h; y += 4)
        for (uint32_t x = 0; x + 8 <= w; x += 4) {
            double ma = 0, mb = 0;
            for (uint32_t j = 0; j < 8; ++j)
                for (uint32_t i = 0; i < 8; ++i) {
                    const size_t p = size_t(y + j) * w + x + i;
                    ma += luma(a, p);
                    mb += luma(b, p);
                }
            ma /= 64;
            mb /= 64;
            double va = 0, vb = 0, cov = 0;
            for (uint32_t j = 0; j < 8; ++j)
                for (uint32_t i = 0; i < 8; ++i) {
                    const size_t p = size_t(y + j) * w + x + i;
                    const double da = luma(a, p) - ma, db = luma(b, p) - mb;
                    va += da * da;
                    vb += db * db;
                    cov += da * db;
                }
            va /= 63;
            vb /= 63;
            cov /= 63;
            ssimSum += ((2 * ma * mb + c1) * (2 * cov + c2)) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
            ++windows;
        }
    d.ssim = windows ? ssimSum / windows : 1.0;
    return d;
}

}  // namespace terralux::test
