#include "terrain/HorizonAO.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include <glm/vec3.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace terralux {
namespace {

void validate(const HorizonAoSettings& s) {
    if (s.directions < 8 || s.directions > 64)
        throw std::invalid_argument("horizon AO: directions = " + std::to_string(s.directions) +
                                    " must be an integer from 8 to 64");
    if (!std::isfinite(s.maxDistance) || s.maxDistance < 0.0)
        throw std::invalid_argument("horizon AO: max distance = " + std::to_string(s.maxDistance) +
                                    " m must be finite and >= 0 (0 = unbounded)");
}

// acos(x) for x in [-1, 1] to 2e-8 rad: Abramowitz and Stegun (1964), 4.4.46. Written without
// branches so that the per-vertex loop vectorises; std::acos would dominate the field's cost.
inline float acosFast(float x) {
    const float ax = std::fabs(x);
    float p = -0.0012624911f;
    p = p * ax + 0.0066700901f;
    p = p * ax - 0.0170881256f;
    p = p * ax + 0.0308918810f;
    p = p * ax - 0.0501743046f;
    p = p * ax + 0.0889789874f;
    p = p * ax - 0.2145988016f;
    p = p * ax + 1.5707963050f;
    const float r = std::sqrt(std::max(0.0f, 1.0f - ax)) * p;
    // acos(−x) = π − acos(x), as arithmetic rather than a select.
    const float sign = std::copysign(1.0f, x);
    return 0.5f * std::numbers::pi_v<float> * (1.0f - sign) + sign * r;
}

// One azimuth slice of the cosine-weighted visibility (Jimenez et al. 2016, GTAO): with the
// direction of elevation θ in the slice ω(θ) = cos θ·t + sin θ·up, n·ω = a cos θ + b sin θ where
// a = n·t and b = n·up > 0. Visible are the elevations above both the horizon h and the normal's
// own horizon h_n (n·ω = 0, tan h_n = −a/b), weighted by the solid angle's cos θ:
//   ∫_{θ0}^{π/2} (a cos θ + b sin θ) cos θ dθ = a (π/2 − θ0 − sin θ0 cos θ0)/2 + b cos² θ0 / 2,
// θ0 = max(h, h_n), from ∫cos² = (θ + sin θ cos θ)/2 and ∫sin cos = sin²/2.
// sinH is sin h (−1 where nothing occludes).
inline float sliceIntegral(float a, float b, float sinH) {
    const float sinN = -a / std::sqrt(a * a + b * b);
    const float s0 = std::max(sinH, sinN);
    const float c0sq = std::max(0.0f, 1.0f - s0 * s0);
    return 0.5f * (a * (acosFast(s0) - s0 * std::sqrt(c0sq)) + b * c0sq);
}

inline float sinOfSlope(double slope) { return float(slope / std::sqrt(1.0 + slope * slope)); }

// The grid seen along the major axis of a sweep: u is the axis the lines step along one cell at
// a time, v the other. transposed: u runs along Z (rows), v along X (columns).
struct Frame {
    const float* h = nullptr;  // row-major in (u, v): h[v * w + u]
    int w = 0, d = 0;
    double cellU = 1, cellV = 1;
    float at(int u, int v) const { return h[size_t(v) * size_t(w) + size_t(u)]; }
};

// One azimuth in frame terms: toward the horizon, each step is (Δu, Δv) = (sigma, slope · sigma)
// cells, `step` metres. (tu, tv): the unit horizontal direction in frame axes.
struct SweepDir {
    bool transposed = false;
    int sigma = 1;
    double slope = 0;  // dv/du of the lines, |slope| <= 1
    double step = 1;
    float tu = 1, tv = 0;
    float tx = 1, tz = 0;  // the same direction in engine space
};

// Azimuth phi (radians), clockwise from north (−Z) toward east (+X) as everywhere in
// docs/lighting.md.
SweepDir sweepDirAt(double phi, double cellX, double cellZ) {
    // Exact zeros on the axes: a rounding residue would tilt the lines off the grid rows.
    const auto snap = [](double v) { return std::fabs(v) < 1e-12 ? 0.0 : v; };
    const double tx = snap(std::sin(phi)), tz = snap(-std::cos(phi));
    SweepDir s;
    s.tx = float(tx);
    s.tz = float(tz);
    const double gx = tx / cellX, gz = tz / cellZ;  // cells per metre
    s.transposed = std::fabs(gx) < std::fabs(gz);
    const double gu = s.transposed ? gz : gx, gv = s.transposed ? gx : gz;
    const double cellU = s.transposed ? cellZ : cellX, cellV = s.transposed ? cellX : cellZ;
    s.sigma = gu > 0 ? 1 : -1;
    const double minorPerStep = gv / std::fabs(gu);
    s.slope = minorPerStep * s.sigma;
    s.step = std::hypot(cellU, minorPerStep * cellV);
    s.tu = float(s.transposed ? tz : tx);
    s.tv = float(s.transposed ? tx : tz);
    return s;
}

// Azimuth k of n.
SweepDir sweepDir(int k, int n, double cellX, double cellZ) {
    return sweepDirAt(2.0 * std::numbers::pi * k / n, cellX, cellZ);
}

// Line k of a sweep crosses column u at v = k + slope·u = k + base[u] + frac[u]: splitting
// slope·u once per column gives every line at that column the same fraction, so the vertex pass
// interpolates between two lines with one weight per column.
// `offset` shifts every line by that share of a cell along v: v = k + offset + slope·u.
struct Columns {
    std::vector<int> base;
    std::vector<float> frac;
    int minBase = 0, maxBase = 0;
    double offset = 0.0;
};

Columns columnsFor(const Frame& f, const SweepDir& s, double offset = 0.0) {
    Columns c;
    c.offset = offset;
    c.base.resize(size_t(f.w));
    c.frac.resize(size_t(f.w));
    for (int u = 0; u < f.w; ++u) {
        const double x = s.slope * u + offset;
        const double b = std::floor(x);
        c.base[size_t(u)] = int(b);
        c.frac[size_t(u)] = float(x - b);
    }
    c.minBase = *std::min_element(c.base.begin(), c.base.end());
    c.maxBase = *std::max_element(c.base.begin(), c.base.end());
    return c;
}

// Sweeps every line of one azimuth, writing the sine of each sample's horizon elevation to
// out[i * w + u], i = floor(v) of the sample at column u. Heights along a line are read where it
// crosses the grid lines u = const; there the triangle surface of Heightfield.h is exactly the
// linear interpolation of the two vertices on that grid line (every cell edge along v is a
// triangle edge), so the samples lie on the mesh the bake traces. The profile between two
// crossings (its kinks at the v grid lines and the diagonals) is not sampled.
// Upper convex hull of a profile walked in t order (Timonen and Westerholm 2010): before (t, h)
// joins the n points kept, drop those nearer than its tangent point; they lie under the segment
// from the tangent point to it. Returns the points left.
int dropUnderHull(const std::vector<double>& ts, const std::vector<double>& hs, int n, double t, double h) {
    while (n >= 2 && (hs[size_t(n - 2)] - h) * (t - ts[size_t(n - 1)]) >= (hs[size_t(n - 1)] - h) * (t - ts[size_t(n - 2)]))
        --n;
    return n;
}

// Appends (t, h) at index n, growing the arrays when a skirt made the profile longer than a row.
void appendSample(std::vector<double>& ts, std::vector<double>& hs, int& n, double t, double h) {
    if (size_t(n) >= ts.size()) {
        ts.resize(size_t(n) + 1);
        hs.resize(size_t(n) + 1);
    }
    ts[size_t(n)] = t;
    hs[size_t(n)] = h;
    ++n;
}

// `behind`, when set, is called at each line's first sample (frame column u, row v, distance tq
// along the walk) to add the profile that lies beyond the grid toward the horizon (the skirt):
// samples (t, h) in walk order, t < tq, appended to ts and hs from index n, returning the new n.
using Behind = std::function<int(int u, double v, double tq, std::vector<double>& ts, std::vector<double>& hs, int n)>;
void sweepHorizons(const Frame& f, const SweepDir& s, const Columns& cols, double maxDistance,
                   float* out, const Behind& behind = {}) {
    const int kLo = -cols.maxBase - 1, kHi = f.d - 1 - cols.minBase;
    tbb::parallel_for(tbb::blocked_range<int>(kLo, kHi + 1, 8), [&](const tbb::blocked_range<int>& r) {
        std::vector<double> ts(size_t(f.w)), hs(size_t(f.w));
        for (int k = r.begin(); k != r.end(); ++k) {
            bool first = true;
            int n = 0;
            double lineMax = -std::numeric_limits<double>::infinity();
            // Columns where the line is inside 0 <= v <= d - 1, one wider each way for rounding
            // (the test below is exact).
            int uLo = 0, uHi = f.w - 1;
            if (s.slope != 0.0) {
                const double ua = (-k - cols.offset) / s.slope, ub = (f.d - 1 - k - cols.offset) / s.slope;
                uLo = std::max(uLo, int(std::floor(std::min(ua, ub))) - 1);
                uHi = std::min(uHi, int(std::ceil(std::max(ua, ub))) + 1);
            } else if (k + cols.offset < 0.0 || k + cols.offset > f.d - 1) {
                continue;
            }
            const int jLo = s.sigma > 0 ? f.w - 1 - uHi : uLo, jHi = s.sigma > 0 ? f.w - 1 - uLo : uHi;
            for (int j = jLo; j <= jHi; ++j) {
                // Walk against the azimuth, so that what lies toward the horizon was seen first.
                const int u = s.sigma > 0 ? f.w - 1 - j : j;
                const int i = k + cols.base[size_t(u)];
                const float g = cols.frac[size_t(u)];
                if (i < 0 || i > f.d - 1 || (i == f.d - 1 && g > 0.0f)) continue;
                const double hq = g > 0.0f ? double(f.at(u, i)) + double(g) * (f.at(u, i + 1) - f.at(u, i))
                                           : double(f.at(u, i));
                const double tq = j * s.step;
                if (first) {
                    first = false;
                    if (behind) {
                        n = behind(u, i + double(g), tq, ts, hs, 0);
                        for (int p = 0; p < n; ++p) lineMax = std::max(lineMax, hs[size_t(p)]);
                    }
                }
                float sinH = -1.0f;
                if (maxDistance <= 0.0) {
                    // The hull's last point after the drop is this sample's tangent point.
                    n = dropUnderHull(ts, hs, n, tq, hq);
                    if (n >= 1) {
                        const double dh = hs[size_t(n - 1)] - hq, dt = tq - ts[size_t(n - 1)];
                        sinH = float(dh / std::sqrt(dh * dh + dt * dt));
                    }
                } else if (n > 0) {
                    // A hull cannot forget the points that fall out of reach, so march back over
                    // the samples within maxDistance, stopping once no remaining sample (none is
                    // above the line's highest so far) can raise the horizon.
                    const double reach = std::min(maxDistance, tq - ts[0]);
                    double best = -std::numeric_limits<double>::infinity();
                    for (int p = n - 1; p >= 0; --p) {
                        const double dt = tq - ts[size_t(p)];
                        if (dt > maxDistance) break;
                        best = std::max(best, (hs[size_t(p)] - hq) / dt);
                        if (best >= (lineMax - hq) / (lineMax >= hq ? dt : reach)) break;
                    }
                    if (best > -std::numeric_limits<double>::infinity()) sinH = sinOfSlope(best);
                }
                appendSample(ts, hs, n, tq, hq);
                lineMax = std::max(lineMax, hq);
                out[size_t(i) * size_t(f.w) + size_t(u)] = sinH;
            }
        }
    });
}

// Adds one azimuth's slice integral at every vertex of the frame. A vertex lies between the
// samples of two neighbouring lines in its column, at the same fraction in every row; its
// horizon is theirs interpolated (Timonen and Westerholm 2010), and exactly its own where a line
// passes through it (axis-aligned azimuths, and diagonals on square cells).
void accumulateSlices(const Frame& f, const SweepDir& s, const Columns& cols, const float* horizon,
                      float* acc) {
    tbb::parallel_for(tbb::blocked_range<int>(0, f.d, 16), [&](const tbb::blocked_range<int>& r) {
        const size_t w = size_t(f.w);
        std::vector<float> invDu(w);
        for (int u = 0; u < f.w; ++u) {
            const int u0 = std::max(u - 1, 0), u1 = std::min(u + 1, f.w - 1);
            invDu[size_t(u)] = u1 > u0 ? float(1.0 / ((u1 - u0) * f.cellU)) : 0.0f;
        }
        std::vector<float> sinH(w);
        for (int v = r.begin(); v != r.end(); ++v) {
            const float* here = horizon + size_t(v) * w;
            const float* above = v > 0 ? horizon + size_t(v - 1) * w : here;
            if (f.d == 1) {
                for (size_t u = 0; u < w; ++u) sinH[u] = cols.frac[u] == 0.0f ? here[u] : -1.0f;
            } else if (v == 0) {
                std::copy(here, here + w, sinH.begin());
            } else if (v == f.d - 1) {
                for (size_t u = 0; u < w; ++u) sinH[u] = cols.frac[u] == 0.0f ? here[u] : above[u];
            } else {
                for (size_t u = 0; u < w; ++u)
                    sinH[u] = (1.0f - cols.frac[u]) * here[u] + cols.frac[u] * above[u];
            }
            // The vertex normal of Heightfield::vertexNormal (central differences), in frame axes.
            const int v0 = std::max(v - 1, 0), v1 = std::min(v + 1, f.d - 1);
            const float invDv = v1 > v0 ? float(1.0 / ((v1 - v0) * f.cellV)) : 0.0f;
            const float* row = f.h + size_t(v) * w;
            const float* row0 = f.h + size_t(v0) * w;
            const float* row1 = f.h + size_t(v1) * w;
            float* a = acc + size_t(v) * w;
            const auto add = [&](size_t u, size_t u0, size_t u1) {
                const float gu = (row[u1] - row[u0]) * invDu[u];
                const float gv = (row1[u] - row0[u]) * invDv;
                const float invLen = 1.0f / std::sqrt(1.0f + gu * gu + gv * gv);
                const float nt = -(gu * s.tu + gv * s.tv) * invLen;
                a[u] += sliceIntegral(nt, invLen, sinH[u]);
            };
            // Interior columns without clamping, so that the loop vectorises.
            for (size_t u = 1; u + 1 < w; ++u) add(u, u - 1, u + 1);
            add(0, 0, std::min<size_t>(1, w - 1));
            if (w > 1) add(w - 1, w - 2, w - 1);
        }
    });
}

std::vector<float> transposed(const std::vector<float>& h, int w, int d) {
    std::vector<float> t(h.size());
    constexpr int kTile = 64;
    tbb::parallel_for(tbb::blocked_range<int>(0, (d + kTile - 1) / kTile), [&](const tbb::blocked_range<int>& r) {
        for (int tr = r.begin(); tr != r.end(); ++tr)
            for (int c0 = 0; c0 < w; c0 += kTile)
                for (int row = tr * kTile; row < std::min(d, (tr + 1) * kTile); ++row)
                    for (int c = c0; c < std::min(w, c0 + kTile); ++c)
                        t[size_t(c) * size_t(d) + size_t(row)] = h[size_t(row) * size_t(w) + size_t(c)];
    });
    return t;
}

}  // namespace

std::vector<float> horizonSkyVisibility(const Heightfield& terrain, const HorizonAoSettings& settings,
                                        const std::function<bool(double)>& progress) {
    validate(settings);
    const int W = terrain.width(), D = terrain.depth(), K = settings.directions;
    const size_t N = size_t(W) * size_t(D);

    std::vector<SweepDir> dirs;
    bool anyTransposed = false;
    for (int k = 0; k < K; ++k) {
        dirs.push_back(sweepDir(k, K, terrain.cellSizeX(), terrain.cellSizeZ()));
        anyTransposed |= dirs.back().transposed;
    }
    // Lines along Z would read one cache line per sample; a transposed copy keeps every sweep
    // walking along memory.
    const std::vector<float> heightsT = anyTransposed ? transposed(terrain.heights(), W, D) : std::vector<float>{};
    const Frame frames[2] = {
        {terrain.heights().data(), W, D, terrain.cellSizeX(), terrain.cellSizeZ()},
        {heightsT.data(), D, W, terrain.cellSizeZ(), terrain.cellSizeX()},
    };
    std::vector<float> acc[2];
    acc[0].assign(N, 0.0f);
    if (anyTransposed) acc[1].assign(N, 0.0f);
    std::vector<float> horizon(N, -1.0f);

    for (int k = 0; k < K; ++k) {
        if (progress && !progress(double(k) / K)) return {};
        const SweepDir& s = dirs[size_t(k)];
        const Frame& f = frames[s.transposed ? 1 : 0];
        const Columns cols = columnsFor(f, s);
        sweepHorizons(f, s, cols, settings.maxDistance, horizon.data());
        accumulateSlices(f, s, cols, horizon.data(), acc[s.transposed ? 1 : 0].data());
    }
    if (progress && !progress(1.0)) return {};

    // Sum of Δφ · slice over π, Δφ = 2π/K.
    const float scale = 2.0f / float(K);
    std::vector<float> out(N);
    tbb::parallel_for(tbb::blocked_range<int>(0, D, 16), [&](const tbb::blocked_range<int>& r) {
        for (int row = r.begin(); row != r.end(); ++row)
            for (int c = 0; c < W; ++c) {
                const size_t i = size_t(row) * size_t(W) + size_t(c);
                float sum = acc[0][i];
                if (anyTransposed) sum += acc[1][size_t(c) * size_t(D) + size_t(row)];
                out[i] = std::clamp(sum * scale, 0.0f, 1.0f);
            }
    });
    return out;
}

float sunDiscAboveHorizon(float horizon, float elevation, float angularRadius) {
    if (!(angularRadius > 0.0f)) return horizon < elevation ? 1.0f : 0.0f;
    // The disc's part above a horizontal chord y radii above its centre: the circular segment's
    // area (acos y − y·sqrt(1 − y²)) over the disc's π.
    const double y = std::clamp((double(horizon) - elevation) / angularRadius, -1.0, 1.0);
    return float((std::acos(y) - y * std::sqrt(1.0 - y * y)) / std::numbers::pi);
}

std::vector<float> sunHorizonVisibility(const Heightfield& terrain, const glm::vec3& toSun, float angularRadius,
                                        bool skirt) {
    const int W = terrain.width(), D = terrain.depth();
    const size_t N = size_t(W) * size_t(D);
    const double len = std::hypot(double(toSun.x), double(toSun.z));
    const float elevation = float(std::atan2(double(toSun.y), len));
    // The sun at the zenith: no terrain of finite slope rises to it.
    if (len < 1e-9) return std::vector<float>(N, 1.0f);
    const SweepDir s = sweepDirAt(std::atan2(double(toSun.x), -double(toSun.z)), terrain.cellSizeX(), terrain.cellSizeZ());
    const std::vector<float> heightsT = s.transposed ? transposed(terrain.heights(), W, D) : std::vector<float>{};
    const Frame f = s.transposed ? Frame{heightsT.data(), D, W, terrain.cellSizeZ(), terrain.cellSizeX()}
                                 : Frame{terrain.heights().data(), W, D, terrain.cellSizeX(), terrain.cellSizeZ()};
    const Columns cols = columnsFor(f, s);

    Behind behind;
    if (skirt) {
        // Beyond the border the surface continues at the nearest border point (Heightfield.h),
        // without end. Past `reach` no skirt point rises to the disc's lower edge from the
        // lowest terrain; once both coordinates are clamped the skirt is level, and its nearest
        // point bounds every farther one for a receiver below it.
        const double lowest = double(elevation) - double(angularRadius);
        const double relief = double(terrain.maxHeight()) - double(terrain.minHeight());
        const double reach = lowest > 1e-4 ? relief / std::tan(lowest) + s.step : 1e7;
        const auto heightAt = [&](double u, double v) {
            const double cu = std::clamp(u, 0.0, double(f.w - 1)), cv = std::clamp(v, 0.0, double(f.d - 1));
            const int iu = std::min(int(cu), f.w - 1), iv = std::min(int(cv), f.d - 1);
            const int ju = std::min(iu + 1, f.w - 1), jv = std::min(iv + 1, f.d - 1);
            const double gu = cu - iu, gv = cv - iv;
            const double a = f.at(iu, iv) + gu * (f.at(ju, iv) - f.at(iu, iv));
            const double b = f.at(iu, jv) + gu * (f.at(ju, jv) - f.at(iu, jv));
            return a + gv * (b - a);
        };
        behind = [=, &f](int u, double v, double tq, std::vector<double>& ts, std::vector<double>& hs, int n) {
            std::vector<std::pair<double, double>> profile;  // (distance beyond, height), nearest first
            double m = 1.0;
            while (true) {
                const double uu = u + s.sigma * m, vv = v + s.slope * s.sigma * m;
                const bool level = (uu < 0.0 || uu > f.w - 1) && (s.slope == 0.0 || vv < 0.0 || vv > f.d - 1);
                const double dist = m * s.step;
                if (dist > reach) break;
                profile.emplace_back(dist, heightAt(uu, vv));
                if (level) {
                    profile.emplace_back(reach, profile.back().second);
                    break;
                }
                // Every cell near the border; farther out, steps growing by 2 %: a far sample
                // subtends little.
                m = m < 256.0 ? m + 1.0 : m * 1.02;
            }
            for (auto it = profile.rbegin(); it != profile.rend(); ++it) {
                const double t = tq - it->first, h = it->second;
                n = dropUnderHull(ts, hs, n, t, h);
                appendSample(ts, hs, n, t, h);
            }
            return n;
        };
    }
    // Two sweeps, the second's lines half a cell from the first's: a vertex is at most a quarter
    // of a cell from a line, where one sweep leaves it up to half a cell from one (a crest
    // between two lines is what a vertex's interpolated horizon misses).
    const Columns half = columnsFor(f, s, 0.5);
    std::vector<float> horizon(N, -1.0f), horizonHalf(N, -1.0f);
    sweepHorizons(f, s, cols, 0.0, horizon.data(), behind);
    sweepHorizons(f, s, half, 0.0, horizonHalf.data(), behind);

    // A vertex's horizon: the nearest line's on each side of it, of either sweep, interpolated.
    std::vector<float> out(N);
    tbb::parallel_for(tbb::blocked_range<int>(0, f.d, 16), [&](const tbb::blocked_range<int>& r) {
        for (int v = r.begin(); v != r.end(); ++v) {
            for (int u = 0; u < f.w; ++u) {
                // Each sweep's line stored in row v lies frac above the vertex (toward v + 1),
                // the one stored in row v − 1 lies 1 − frac below; a line past the last row is
                // not stored, and neither is a row before the first.
                float upD = 2.0f, upH = -1.0f, downD = 2.0f, downH = -1.0f;
                for (int k = 0; k < 2; ++k) {
                    const float* h = (k == 0 ? horizon : horizonHalf).data();
                    const float g = (k == 0 ? cols : half).frac[size_t(u)];
                    if ((v < f.d - 1 || g == 0.0f) && g < upD) {
                        upD = g;
                        upH = h[size_t(v) * size_t(f.w) + size_t(u)];
                    }
                    if (v > 0 && 1.0f - g < downD) {
                        downD = 1.0f - g;
                        downH = h[size_t(v - 1) * size_t(f.w) + size_t(u)];
                    }
                }
                float sinH = -1.0f;
                if (upD == 0.0f || downD > 1.5f) sinH = upD < 1.5f ? upH : -1.0f;
                else if (upD > 1.5f) sinH = downH;
                else sinH = (downD * upH + upD * downH) / (upD + downD);
                const float vis = sunDiscAboveHorizon(std::asin(std::clamp(sinH, -1.0f, 1.0f)), elevation, angularRadius);
                const size_t i = s.transposed ? size_t(u) * size_t(W) + size_t(v) : size_t(v) * size_t(W) + size_t(u);
                out[i] = vis;
            }
        }
    });
    return out;
}

float horizonSkyVisibilityAt(const Heightfield& terrain, const HorizonAoSettings& settings, float x, float z) {
    validate(settings);
    if (!terrain.contains(x, z))
        throw std::invalid_argument("horizon AO: point (" + std::to_string(x) + ", " + std::to_string(z) +
                                    ") must lie inside the footprint [" + std::to_string(terrain.minX()) + ", " +
                                    std::to_string(terrain.maxX()) + "] x [" + std::to_string(terrain.minZ()) +
                                    ", " + std::to_string(terrain.maxZ()) + "]");
    const int W = terrain.width(), D = terrain.depth(), K = settings.directions;
    const glm::vec3 n = terrain.surfaceNormal(x, z);
    const double h0 = terrain.surfaceHeight(x, z);
    const double gx = terrain.colOf(x);
    const double gz = terrain.rowOf(z);
    double sum = 0.0;
    for (int k = 0; k < K; ++k) {
        const SweepDir s = sweepDir(k, K, terrain.cellSizeX(), terrain.cellSizeZ());
        const int w = s.transposed ? D : W, d = s.transposed ? W : D;
        const double pu = s.transposed ? gz : gx, pv = s.transposed ? gx : gz;
        // Height where the ray crosses the grid line u, at v: the same samples as the sweep's.
        const auto heightAt = [&](int u, double v) {
            const int i = std::min(int(v), d - 1);
            const double g = v - i;
            const auto h = [&](int vv) { return double(s.transposed ? terrain.at(vv, u) : terrain.at(u, vv)); };
            return g > 0.0 && i + 1 < d ? h(i) + g * (h(i + 1) - h(i)) : h(i);
        };
        double best = -std::numeric_limits<double>::infinity();
        for (int u = s.sigma > 0 ? int(std::floor(pu)) + 1 : int(std::ceil(pu)) - 1; u >= 0 && u < w; u += s.sigma) {
            const double du = std::fabs(u - pu);
            const double dist = du * s.step;
            if (settings.maxDistance > 0.0 && dist > settings.maxDistance) break;
            const double v = pv + s.slope * (u - pu);
            if (v < 0.0 || v > d - 1) break;
            best = std::max(best, (heightAt(u, v) - h0) / dist);
        }
        const float sinH = best > -std::numeric_limits<double>::infinity() ? sinOfSlope(best) : -1.0f;
        sum += sliceIntegral(n.x * s.tx + n.z * s.tz, n.y, sinH);
    }
    return std::clamp(float(sum * 2.0 / K), 0.0f, 1.0f);
}

}  // namespace terralux
