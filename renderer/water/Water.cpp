#include "water/Water.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <numbers>
#include <sstream>

#include <glm/geometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "terrain/DerivedCache.h"

namespace terralux::water {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();

// A number as the messages print it: up to 6 significant digits.
std::string show(double v) {
    std::ostringstream s;
    s.precision(6);
    s << v;
    return s.str();
}

// One line of the squared Euclidean distance transform of Felzenszwalb and Huttenlocher,
// "Distance Transforms of Sampled Functions", Theory of Computing 8 (2012), algorithm DT(f):
// out[p] = min_q ((p − q)·spacing)² + f[q], the lower envelope of the parabolas rooted at each
// sample, in O(n). Samples with f = +∞ root no parabola; a line without any stays +∞.
// `v` and `z` are scratch of at least n and n + 1 entries.
void distanceTransform1d(const double* f, int n, double spacing, double* out, int* v, double* z) {
    const double s2 = spacing * spacing;
    // Where the parabolas of q and r (q > r) cross, in sample units (the paper's s, scaled).
    auto cross = [&](int q, int r) {
        return ((f[q] + s2 * double(q) * double(q)) - (f[r] + s2 * double(r) * double(r))) /
               (2.0 * s2 * double(q - r));
    };
    int k = -1;
    for (int q = 0; q < n; ++q) {
        if (!std::isfinite(f[q])) continue;
        if (k < 0) {
            k = 0;
            v[0] = q;
            z[0] = -kInf;
            z[1] = kInf;
            continue;
        }
        double s = cross(q, v[k]);
        while (s <= z[k]) {  // z[0] = −∞ stops this at k = 0
            --k;
            s = cross(q, v[k]);
        }
        ++k;
        v[k] = q;
        z[k] = s;
        z[k + 1] = kInf;
    }
    if (k < 0) {
        std::fill(out, out + n, kInf);
        return;
    }
    k = 0;
    for (int p = 0; p < n; ++p) {
        while (z[k + 1] < double(p)) ++k;
        const double d = spacing * double(p - v[k]);
        out[p] = d * d + f[v[k]];
    }
}

// A preset wave: direction, wavelength, steepness k·A and phase.
GerstnerWave presetWave(double directionDeg, double wavelength, double steepness, double phase) {
    GerstnerWave w;
    w.directionDeg = directionDeg;
    w.wavelength = wavelength;
    w.steepness = steepness;
    w.phase = phase;
    return w;
}

}  // namespace

WaveTerms waveTerms(const GerstnerWave& wave) {
    WaveTerms t;
    // Azimuth a clockwise from north (−Z) toward east (+X): (sin a, −cos a) in (x, z), the
    // convention of the sun (docs/lighting.md, "Units and axes").
    const double a = wave.directionDeg * kPi / 180.0;
    t.direction = {std::sin(a), -std::cos(a)};
    t.k = 2.0 * kPi / wave.wavelength;
    t.amplitude = wave.amplitude ? *wave.amplitude : wave.steepness.value_or(0.0) / t.k;
    t.omegaDeep = angularFrequency(t.k, std::nullopt);
    t.phase = wave.phase;
    return t;
}

double angularFrequency(double k, std::optional<double> depth) {
    // The dispersion relation of linear (Airy) waves over a bed at depth h: ω² = g·k·tanh(k·h),
    // which is g·k in deep water (k·h → ∞) and g·h·k² in shallow water (Tessendorf, "Simulating
    // Ocean Water", SIGGRAPH 2001 course notes, "dispersion relation"). Dry ground (h <= 0)
    // holds a wave still.
    if (!depth) return std::sqrt(kGravity * k);
    return glsl::dbl::waveOmegaAtDepth(k, *depth);
}

double summedSteepness(const std::vector<GerstnerWave>& waves) {
    double sum = 0.0;
    for (const GerstnerWave& w : waves) {
        const WaveTerms t = waveTerms(w);
        sum += t.k * t.amplitude;
    }
    return sum;
}

std::string checkWaves(const std::vector<GerstnerWave>& waves) {
    if (waves.size() > size_t(WaterSettings::kMaxWaves))
        return "must hold at most " + std::to_string(WaterSettings::kMaxWaves) + " waves (has " +
               std::to_string(waves.size()) + ")";
    for (size_t i = 0; i < waves.size(); ++i) {
        const GerstnerWave& w = waves[i];
        const std::string at = "wave " + std::to_string(i) + ": ";
        if (!std::isfinite(w.directionDeg)) return at + "direction_deg must be finite";
        if (!std::isfinite(w.phase)) return at + "phase must be finite";
        if (!(std::isfinite(w.wavelength) && w.wavelength > 0.0))
            return at + "wavelength must be > 0 (is " + show(w.wavelength) + ")";
        if (w.amplitude.has_value() == w.steepness.has_value())
            return at + "must set exactly one of amplitude and steepness";
        if (w.amplitude && !(std::isfinite(*w.amplitude) && *w.amplitude >= 0.0))
            return at + "amplitude must be >= 0 (is " + show(*w.amplitude) + ")";
        if (w.steepness && !(*w.steepness >= 0.0 && *w.steepness <= 1.0))
            return at + "steepness must be in [0, 1] (is " + show(*w.steepness) + ")";
    }
    // With Q_i = 1 the tangent along a wave is 1 − Σ k_i·A_i·sin θ_i (gerstner below): where the
    // sum passes 1 the surface folds over into a loop at the crests (Tessendorf 2001, "choppy
    // waves"; Finch 2004). At most 1 keeps it a function of its rest position.
    const double sum = summedSteepness(waves);
    if (!(sum <= 1.0))
        return "summed steepness Σ k·A must be <= 1, or the crests loop (is " + show(sum) + ")";
    return "";
}

SurfacePoint gerstner(const std::vector<WaveTerms>& waves, glm::dvec2 xz, double t,
                      std::optional<double> depth, double fade) {
    // The terms of water_math.glsl, which the water shaders evaluate in float.
    SurfacePoint out;
    glm::dvec3 tx(1.0, 0.0, 0.0), tz(0.0, 0.0, 1.0);
    for (const WaveTerms& w : waves) {
        const double omega = depth ? angularFrequency(w.k, depth) : w.omegaDeep;
        glsl::dbl::gerstnerAdd(w.direction, w.k, w.amplitude * fade,
                               glsl::dbl::gerstnerPhase(w.direction, w.k, xz, omega, t, w.phase), out.displacement,
                               tx, tz);
    }
    out.normal = glsl::dbl::gerstnerNormal(tx, tz);
    return out;
}

double shoreFade(double distance, double fadeDistance) { return glsl::dbl::waveShoreFade(distance, fadeDistance); }

namespace {

AutoLevel findLevel(const Heightfield& hf) {
    const int w = hf.width(), d = hf.depth();
    const size_t n = size_t(w) * size_t(d);
    const std::vector<float>& h = hf.heights();
    AutoLevel out;
    const size_t minCells = std::max(kMinWaterCells, n / 10000);
    // Flat areas, each gathered from its first cell: a neighbour within the tolerance of that
    // cell's height joins it (no drift along a gentle slope).
    struct Surface {
        float level;
        size_t cells;
    };
    std::vector<Surface> found;
    std::vector<uint8_t> seen(n, 0);
    std::vector<uint32_t> stack;
    for (size_t start = 0; start < n; ++start) {
        if (seen[start]) continue;
        const float level = h[start];
        seen[start] = 1;
        stack.assign(1, uint32_t(start));
        size_t cells = 0;
        bool minimum = true;
        while (!stack.empty()) {
            const uint32_t i = stack.back();
            stack.pop_back();
            ++cells;
            const int x = int(i % uint32_t(w)), z = int(i / uint32_t(w));
            const auto visit = [&](int nx, int nz) {
                if (nx < 0 || nz < 0 || nx >= w || nz >= d) return;
                const size_t j = size_t(nz) * size_t(w) + size_t(nx);
                const float dh = h[j] - level;
                if (dh < -kFlatTolerance) minimum = false;
                if (seen[j] || std::abs(dh) > kFlatTolerance) return;
                seen[j] = 1;
                stack.push_back(uint32_t(j));
            };
            visit(x - 1, z);
            visit(x + 1, z);
            visit(x, z - 1);
            visit(x, z + 1);
        }
        if (minimum && cells >= minCells) found.push_back({level, cells});
    }
    // A plane at a surface's level floods everything below it: keep a surface only when the dry
    // land under its level is at most a tenth of its own area.
    std::sort(found.begin(), found.end(), [](const Surface& a, const Surface& b) {
        return a.cells != b.cells ? a.cells > b.cells : a.level < b.level;
    });
    size_t rejected = 0;
    if (found.size() > 16) found.resize(16);
    for (const Surface& s : found) {
        size_t below = 0;
        for (float v : h) below += v < s.level - kFlatTolerance;
        if (below * 10 > s.cells) {
            ++rejected;
            continue;
        }
        out.level = double(s.level);
        out.cells = s.cells;
        out.share = double(s.cells) / double(n);
        std::ostringstream line;
        line << "a flat water surface at " << s.level << " m over " << std::setprecision(3)
             << 100.0 * out.share << " % of the DEM's cells";
        out.summary = line.str();
        return out;
    }
    std::ostringstream line;
    line << "the DEM shows no water surface (no flat area of at least " << minCells
         << " cells that is a local minimum";
    if (rejected > 0) line << " without flooding dry land below it; " << rejected << " would";
    line << ")";
    out.summary = line.str();
    return out;
}

}  // namespace

AutoLevel autoLevel(const Heightfield& hf) {
    // 10 ms on a 1201² tile, asked for by every edit the viewport draws with water on.
    static DerivedCache<AutoLevel> kept;
    return *kept.get(hf.serial(), "", [&] { return findLevel(hf); });
}

std::optional<double> waterLevel(const WaterSettings& settings, const Heightfield& hf) {
    if (settings.level) return *settings.level;
    return autoLevel(hf).level;
}

double shoreFadeDistance(const WaterSettings& settings, const Heightfield& hf) {
    if (settings.shoreFadeDistance) return *settings.shoreFadeDistance;
    return 2.0 * std::max(hf.cellSizeX(), hf.cellSizeZ());
}

std::vector<float> shoreDistance(const Heightfield& hf, double level) {
    const int w = hf.width(), d = hf.depth();
    const size_t n = size_t(w) * size_t(d);
    std::vector<double> sq(n);
    const std::vector<float>& h = hf.heights();
    for (size_t i = 0; i < n; ++i) sq[i] = double(h[i]) >= level ? 0.0 : kInf;

    // Separable: the exact 2-D transform is the 1-D transform along x, then along z of that
    // (Felzenszwalb and Huttenlocher 2012, section 3), each with its own cell size.
    tbb::parallel_for(tbb::blocked_range<int>(0, d), [&](const tbb::blocked_range<int>& rows) {
        const size_t n1 = size_t(w);
        std::vector<double> f(n1), out(n1), z(n1 + 1);
        std::vector<int> v(n1);
        for (int r = rows.begin(); r != rows.end(); ++r) {
            double* line = &sq[size_t(r) * size_t(w)];
            std::copy(line, line + w, f.begin());
            distanceTransform1d(f.data(), w, hf.cellSizeX(), out.data(), v.data(), z.data());
            std::copy(out.begin(), out.end(), line);
        }
    });
    std::vector<float> distance(n);
    tbb::parallel_for(tbb::blocked_range<int>(0, w), [&](const tbb::blocked_range<int>& cols) {
        const size_t n1 = size_t(d);
        std::vector<double> f(n1), out(n1), z(n1 + 1);
        std::vector<int> v(n1);
        for (int c = cols.begin(); c != cols.end(); ++c) {
            for (int r = 0; r < d; ++r) f[size_t(r)] = sq[size_t(r) * size_t(w) + size_t(c)];
            distanceTransform1d(f.data(), d, hf.cellSizeZ(), out.data(), v.data(), z.data());
            for (int r = 0; r < d; ++r)
                distance[size_t(r) * size_t(w) + size_t(c)] = float(std::sqrt(out[size_t(r)]));
        }
    });
    return distance;
}

std::vector<std::string> wavePresetNames() { return {"calm lake", "choppy lake", "open sea"}; }

std::vector<GerstnerWave> wavePreset(const std::string& name) {
    // Steepness k·A of each wave: a wave breaks near k·A = 0.44 (the limiting wave of Michell
    // 1893, H/λ = 0.142, with A = H/2); the presets stay at 0.04 to 0.1 per wave, so even their
    // sum keeps well inside the rule of checkWaves. The shorter waves are the steeper, the
    // directions spread about one wind direction, and the phases are spread so that no two
    // crests line up at the origin.
    if (name == "calm lake")
        return {presetWave(40.0, 4.0, 0.04, 0.0), presetWave(65.0, 2.6, 0.05, 2.4),
                presetWave(20.0, 1.7, 0.05, 4.8)};
    if (name == "choppy lake")
        return {presetWave(40.0, 9.0, 0.08, 0.0), presetWave(70.0, 6.0, 0.09, 2.4),
                presetWave(15.0, 4.2, 0.10, 4.8), presetWave(55.0, 2.8, 0.10, 0.9),
                presetWave(25.0, 1.9, 0.08, 3.3)};
    if (name == "open sea")
        // A long swell from farther away, then the local wind sea on it.
        return {presetWave(10.0, 90.0, 0.06, 0.0), presetWave(35.0, 45.0, 0.08, 2.4),
                presetWave(60.0, 28.0, 0.09, 4.8), presetWave(20.0, 17.0, 0.10, 0.9),
                presetWave(50.0, 11.0, 0.10, 3.3), presetWave(30.0, 7.0, 0.09, 5.7),
                presetWave(75.0, 4.5, 0.08, 1.8), presetWave(5.0, 3.0, 0.07, 4.2)};
    return {};
}

}  // namespace terralux::water
