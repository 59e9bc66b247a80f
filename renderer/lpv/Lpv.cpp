#include "lpv/Lpv.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "ShaderMath.h"
#include "bake/SphereSampling.h"

namespace terralux::lpv {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;
using glsl::kShY00;  // the SH basis constants the shaders use (sh_basis.glsl)
using glsl::kShY1;
using glsl::kShY20;
// Solid angles a cell's centre sees of a neighbour's faces (Kaplanyan & Dachsbacher 2010, Sec. 5.2):
// the far face, a unit square 1.5 cells away, and each side face. 0.4006696846 + 4 · 0.4234413544 =
// 2π/3, so the six neighbours' thirty faces cover the sphere.
constexpr float kFarFace = 0.4006696846f;
constexpr float kSideFace = 0.4234413544f;
constexpr int kHalf = kGrid / 2;

using Face = PropagationFace;
using Neighbour = PropagationNeighbour;
const std::array<Neighbour, 6>& neighbours() { return propagationNeighbours(); }

Sh4 cellSh(const LightVolume& v, int channel, size_t cell) {
    const float* c = &v[lightOffset(channel, cell, 0)];
    return {c[0], c[1], c[2], c[3]};
}

Sh4 cornerSh(const GeometryVolume& g, size_t corner) {
    const float* c = &g[corner * 4];
    return {c[0], c[1], c[2], c[3]};
}

// Blocking SH on the face between cell s and its neighbour along `nb`: the mean of the face's
// four corner texels (the face centre, bilinearly).
Sh4 faceGeometry(const GeometryVolume& g, const glm::ivec3& s, const Neighbour& nb) {
    glm::ivec3 base = s;
    if (nb.offset[nb.axis] > 0) base[nb.axis] += 1;
    const int o1 = (nb.axis + 1) % 3, o2 = (nb.axis + 2) % 3;
    Sh4 sum{};
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) {
            glm::ivec3 c = base;
            c[o1] += i;
            c[o2] += j;
            const Sh4 t = cornerSh(g, cornerIndex(c.x, c.y, c.z));
            for (int k = 0; k < 4; ++k) sum[k] += 0.25f * t[k];
        }
    return sum;
}

bool inside(const glm::ivec3& c) {
    return c.x >= 0 && c.y >= 0 && c.z >= 0 && c.x < kGrid && c.y < kGrid && c.z < kGrid;
}

// Per source cell and channel, the factor that makes its non-negative face fluxes sum to its flux.
std::vector<float> sendScales(const LightVolume& src) {
    std::vector<float> scale(size_t(3) * kCells, 0.0f);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, kCells, 1024), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t cell = r.begin(); cell != r.end(); ++cell)
            for (int ch = 0; ch < 3; ++ch) {
                const Sh4 sh = cellSh(src, ch, cell);
                const float flux = 2.0f * std::sqrt(kPi) * sh[0];
                if (!(flux > 0.0f)) continue;
                float positive = 0.0f;
                for (const Neighbour& nb : neighbours())
                    for (const Face& f : nb.faces) positive += std::max(0.0f, evaluate(sh, f.dir)) * f.solidAngle;
                if (positive > 0.0f) scale[size_t(ch) * kCells + cell] = flux / positive;
            }
    });
    return scale;
}

template <typename Body>
void forSlices(Body body) {
    tbb::parallel_for(tbb::blocked_range<int>(0, kGrid, 1), [&](const tbb::blocked_range<int>& r) {
        for (int z = r.begin(); z != r.end(); ++z) body(z);
    });
}

glm::vec3 reflectDir(const glm::vec3& incident, const glm::vec3& n) { return incident - 2.0f * glm::dot(n, incident) * n; }

}  // namespace

// ---- SH ---------------------------------------------------------------------------------------

Sh4 basis(const glm::vec3& d) { return {kShY00, kShY1 * d.y, kShY1 * d.z, kShY1 * d.x}; }

float evaluate(const Sh4& sh, const glm::vec3& d) {
    return sh[0] * kShY00 + kShY1 * (sh[1] * d.y + sh[2] * d.z + sh[3] * d.x);
}

Sh4 clampedCosine(const glm::vec3& n, float scale) {
    const float a0 = kPi * kShY00 * scale, a1 = (2.0f * kPi / 3.0f) * kShY1 * scale;
    return {a0, a1 * n.y, a1 * n.z, a1 * n.x};
}

float irradianceLinear(const Sh4& l, const glm::vec3& n) {
    return kPi * kShY00 * l[0] + (2.0f * kPi / 3.0f) * kShY1 * (l[1] * n.y + l[2] * n.z + l[3] * n.x);
}

float irradianceZh3(const Sh4& l, float z2, const glm::vec3& axis, const glm::vec3& n) {
    const float t = glm::dot(axis, n);
    return irradianceLinear(l, n) + 0.25f * kPi * z2 * kShY20 * (3.0f * t * t - 1.0f);
}

float hallucinatedZonal(const Sh4& l, const glm::vec3& axis) {
    if (!(l[0] > 0.0f)) return 0.0f;
    const float ratio = std::abs(l[3] * axis.x + l[1] * axis.y + l[2] * axis.z) / l[0];
    return l[0] * (0.08f * ratio + 0.6f * ratio * ratio);
}

glm::vec3 irradianceZh3Hallucinated(const std::array<Sh4, 3>& rgb, const glm::vec3& n) {
    const glm::vec3 lum(glsl::rec709Luminance(rgb[0][3], rgb[1][3], rgb[2][3]),
                        glsl::rec709Luminance(rgb[0][1], rgb[1][1], rgb[2][1]),
                        glsl::rec709Luminance(rgb[0][2], rgb[1][2], rgb[2][2]));
    const float len = glm::length(lum);
    glm::vec3 out;
    for (int c = 0; c < 3; ++c) {
        if (!(len > 1e-20f)) {
            out[c] = irradianceLinear(rgb[c], n);
            continue;
        }
        const glm::vec3 axis = lum / len;
        out[c] = irradianceZh3(rgb[c], hallucinatedZonal(rgb[c], axis), axis, n);
    }
    return out;
}

// ---- Propagation's faces -----------------------------------------------------------------------

const std::array<PropagationNeighbour, 6>& propagationNeighbours() {
    static const std::array<PropagationNeighbour, 6> table = [] {
        std::array<PropagationNeighbour, 6> t{};
        int n = 0;
        for (int axis = 0; axis < 3; ++axis)
            for (int sign : {1, -1}) {
                PropagationNeighbour& nb = t[size_t(n++)];
                nb.offset = glm::ivec3(0);
                nb.offset[axis] = sign;
                nb.axis = axis;
                const glm::vec3 a(nb.offset);
                nb.faces[0] = {a, kFarFace, clampedCosine(a, 1.0f / kPi)};
                int f = 1;
                for (int other = 0; other < 3; ++other) {
                    if (other == axis) continue;
                    for (int s : {1, -1}) {
                        glm::vec3 b(0.0f);
                        b[other] = float(s);
                        nb.faces[size_t(f++)] = {glm::normalize(a + 0.5f * b), kSideFace, clampedCosine(b, 1.0f / kPi)};
                    }
                }
            }
        return t;
    }();
    return table;
}

// ---- Cascades ---------------------------------------------------------------------------------

double autoSize(const Heightfield& terrain) {
    const double side = std::max(double(terrain.maxX()) - double(terrain.minX()),
                                 double(terrain.maxZ()) - double(terrain.minZ()));
    const double cells = double(kGrid) * std::max(terrain.cellSizeX(), terrain.cellSizeZ());
    return std::min(std::max(side, cells), 1.0e6);
}

LpvSettings resolvedOn(LpvSettings settings, const Heightfield& terrain) {
    if (!settings.size) settings.size = autoSize(terrain);
    return settings;
}

double sizeOf(const LpvSettings& s) {
    if (!s.size) throw std::logic_error("lpv.size is unresolved: resolve it on the terrain (lpv::resolvedOn) first");
    return *s.size;
}

double cascadeRatio(const LpvSettings& s) {
    double r = s.cascadeRatio;
    if (s.autoCascadeMinSize > 0.0 && s.cascades > 1)
        r = std::max(r, std::pow(sizeOf(s) / s.autoCascadeMinSize, 1.0 / double(s.cascades - 1)));
    return r;
}

std::vector<double> cascadeSizes(const LpvSettings& s) {
    const double r = cascadeRatio(s);
    std::vector<double> sizes;
    for (int i = 0; i < s.cascades; ++i) sizes.push_back(sizeOf(s) / std::pow(r, double(i)));
    return sizes;
}

glm::dvec3 CascadeLayout::origin() const {
    return glm::dvec3(double(originCell[0]), double(originCell[1]), double(originCell[2])) * cellSize;
}
glm::dvec3 CascadeLayout::centre() const { return origin() + glm::dvec3(0.5 * size); }
bool CascadeLayout::contains(const glm::dvec3& p) const {
    const glm::dvec3 o = origin();
    for (int a = 0; a < 3; ++a)
        if (!(p[a] >= o[a] && p[a] <= o[a] + size)) return false;
    return true;
}

std::vector<CascadeLayout> placeCascades(const LpvSettings& s, const glm::dvec3& camera, const glm::dvec3& viewDir) {
    const double len = glm::length(viewDir);
    const glm::dvec3 v = len > 0.0 ? viewDir / len : glm::dvec3(0.0);
    std::vector<CascadeLayout> out;
    for (double size : cascadeSizes(s)) {
        CascadeLayout c;
        c.size = size;
        c.cellSize = size / kGrid;
        c.wanted = camera + s.cascadeForwardOffset * size * v;
        for (int a = 0; a < 3; ++a) c.originCell[a] = (long long)std::floor(c.wanted[a] / c.cellSize) - kHalf;
        out.push_back(c);
    }
    return out;
}

// ---- Volumes ----------------------------------------------------------------------------------

LightVolume emptyLightVolume() { return LightVolume(size_t(3) * kCells * 4, 0.0f); }
GeometryVolume emptyGeometryVolume() { return GeometryVolume(size_t(kCornerCount) * 4, 0.0f); }

glm::dvec3 totalFlux(const LightVolume& v) {
    glm::dvec3 sum(0.0);
    for (int ch = 0; ch < 3; ++ch)
        for (size_t cell = 0; cell < size_t(kCells); ++cell) sum[ch] += v[lightOffset(ch, cell, 0)];
    return sum * (2.0 * std::sqrt(std::numbers::pi));
}

double lightRange(const LightVolume& injected, double cellSize, double indirectIntensity) {
    std::vector<double> radiance;
    const double kY00 = kShY00;
    for (size_t cell = 0; cell < size_t(kCells); ++cell) {
        const double y = glsl::rec709Luminance(injected[lightOffset(0, cell, 0)], injected[lightOffset(1, cell, 0)],
                                               injected[lightOffset(2, cell, 0)]);
        if (y > 0.0) radiance.push_back(y * kY00 / (cellSize * cellSize) * indirectIntensity);
    }
    if (radiance.empty()) return 0.0;
    // Nearest rank, as the report's percentiles.
    const size_t rank = std::max<size_t>(1, size_t(std::ceil(0.99 * double(radiance.size()))));
    std::nth_element(radiance.begin(), radiance.begin() + std::ptrdiff_t(rank - 1), radiance.end());
    return radiance[rank - 1];
}

void addBlocker(GeometryVolume& g, size_t corner, const glm::vec3& normal, float areaOverCellArea) {
    const Sh4 lobe = clampedCosine(normal, areaOverCellArea * (4.0f / 3.0f));
    for (int k = 0; k < 4; ++k) g[corner * 4 + k] += lobe[k];
}

float blocking(const Sh4& geometry, const glm::vec3& dir) {
    return std::clamp(evaluate(geometry, -dir), 0.0f, 1.0f);
}

void injectLobe(LightVolume& v, size_t cell, const glm::vec3& normal, const glm::vec3& flux) {
    // I(ω) = flux/π · max(0, n·ω): coefficients flux·Y_0 and (2/3)·flux·Y_1(n).
    for (int ch = 0; ch < 3; ++ch) {
        const Sh4 lobe = clampedCosine(normal, flux[ch] / kPi);
        for (int k = 0; k < 4; ++k) v[lightOffset(ch, cell, k)] += lobe[k];
    }
}

void propagationStep(const GeometryVolume& geometry, const LightVolume& src, LightVolume& dst, float weight,
                     bool occlude, PropagationStats* stats) {
    dst.assign(src.size(), 0.0f);
    const std::vector<float> scale = sendScales(src);
    // Gather: each destination cell sums what its six neighbours send it, in a fixed order.
    forSlices([&](int z) {
        for (int y = 0; y < kGrid; ++y)
            for (int x = 0; x < kGrid; ++x) {
                const glm::ivec3 t(x, y, z);
                const size_t tc = cellIndex(x, y, z);
                for (const Neighbour& nb : neighbours()) {
                    const glm::ivec3 s = t - nb.offset;
                    if (!inside(s)) continue;
                    const size_t sc = cellIndex(s.x, s.y, s.z);
                    const Sh4 g = occlude ? faceGeometry(geometry, s, nb) : Sh4{};
                    for (const Face& f : nb.faces) {
                        const float transmit = occlude ? 1.0f - blocking(g, f.dir) : 1.0f;
                        for (int ch = 0; ch < 3; ++ch) {
                            const float k = scale[size_t(ch) * kCells + sc];
                            if (k == 0.0f) continue;
                            const float flux = k * std::max(0.0f, evaluate(cellSh(src, ch, sc), f.dir)) *
                                               f.solidAngle * weight * transmit;
                            for (int c = 0; c < 4; ++c) dst[lightOffset(ch, tc, c)] += flux * f.lobe[c];
                        }
                    }
                }
            }
    });
    if (!stats) return;
    // The same fluxes seen from the sources, per slice, summed in slice order.
    std::vector<std::array<glm::dvec3, 3>> perSlice(kGrid);
    forSlices([&](int z) {
        std::array<glm::dvec3, 3> acc{};
        for (int y = 0; y < kGrid; ++y)
            for (int x = 0; x < kGrid; ++x) {
                const glm::ivec3 s(x, y, z);
                const size_t sc = cellIndex(x, y, z);
                for (const Neighbour& nb : neighbours()) {
                    const bool out = !inside(s + nb.offset);
                    const Sh4 g = occlude && !out ? faceGeometry(geometry, s, nb) : Sh4{};
                    for (const Face& f : nb.faces) {
                        const float transmit = occlude && !out ? 1.0f - blocking(g, f.dir) : 1.0f;
                        for (int ch = 0; ch < 3; ++ch) {
                            const double flux = double(scale[size_t(ch) * kCells + sc]) *
                                                std::max(0.0f, evaluate(cellSh(src, ch, sc), f.dir)) *
                                                f.solidAngle * weight;
                            if (out) acc[1][ch] += flux;
                            else {
                                acc[0][ch] += flux * transmit;
                                acc[2][ch] += flux * (1.0 - transmit);
                            }
                        }
                    }
                }
            }
        perSlice[size_t(z)] = acc;
    });
    *stats = PropagationStats{};
    for (const auto& a : perSlice) {
        stats->sent += a[0];
        stats->leaving += a[1];
        stats->blocked += a[2];
    }
}

// ---- Volumes of a scene -----------------------------------------------------------------------

namespace {

// Lift a point off the surface by more than the tracer's self-hit distance (as the bake does).
glm::vec3 liftOff(const glm::vec3& p, const glm::vec3& n) {
    const float m = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    return p + n * (1e-5f * m + 1e-2f);
}

// One emitter, computed in parallel into its slot and injected in slot order.
struct Emitter {
    long long cell = -1;  // -1: none
    glm::vec3 normal{0.0f};
    glm::vec3 flux{0.0f};
};

// The surfel at column (i, k) of a cascade, sub-sample (a, b): its position, normal and area.
struct Surfel {
    glm::vec3 p, n;
    float area;
    bool onTerrain;
};

Surfel surfelAt(const Heightfield& hf, const CascadeLayout& c, int i, int k, int a, int b) {
    const glm::dvec3 o = c.origin();
    const double step = c.cellSize / kSurfelsPerCell;
    const float x = float(o.x + (i * kSurfelsPerCell + a + 0.5) * step);
    const float z = float(o.z + (k * kSurfelsPerCell + b + 0.5) * step);
    Surfel s;
    s.p = glm::vec3(x, hf.surfaceHeight(x, z), z);
    s.n = hf.surfaceNormal(x, z);
    // The true area of the patch over a step² of ground.
    s.area = float(step * step) / std::max(s.n.y, 1e-3f);
    s.onTerrain = hf.contains(x, z);
    return s;
}

long long cellOf(const CascadeLayout& c, const glm::vec3& p) {
    const glm::dvec3 u = (glm::dvec3(p) - c.origin()) / c.cellSize;
    glm::ivec3 i;
    for (int a = 0; a < 3; ++a) {
        if (!(u[a] >= 0.0 && u[a] < kGrid)) return -1;
        i[a] = int(u[a]);
    }
    return (long long)cellIndex(i.x, i.y, i.z);
}

void injectAll(LightVolume& v, const std::vector<Emitter>& emitters) {
    for (const Emitter& e : emitters)
        if (e.cell >= 0) injectLobe(v, size_t(e.cell), e.normal, e.flux);
}

uint64_t surfelSeed(const CascadeLayout& c, int cascade, int i, int k, int a, int b) {
    const long long wx = (c.originCell[0] + i) * kSurfelsPerCell + a;
    const long long wz = (c.originCell[2] + k) * kSurfelsPerCell + b;
    return splitmix64(uint64_t(wx) * 0x9E3779B97F4A7C15ull ^ uint64_t(wz) * 0xC2B2AE3D27D4EB4Full ^ uint64_t(cascade));
}

float lightAttenuation(const LocalLight& l, const glm::vec3& toSurfel, float d) {
    // KHR_lights_punctual's recommended range window and spot falloff.
    const float ratio = d / float(l.range);
    const float window = std::clamp(1.0f - ratio * ratio * ratio * ratio, 0.0f, 1.0f);
    const float dd = std::max(d, 0.01f);
    float att = window / (dd * dd);
    if (l.type == LocalLightType::Spot) {
        const glm::vec3 axis = glm::normalize(l.direction);
        const float cosOuter = std::cos(float(l.outerConeDeg) * kPi / 180.0f);
        const float cosInner = std::cos(float(l.innerConeDeg) * kPi / 180.0f);
        const float scale = 1.0f / std::max(0.001f, cosInner - cosOuter);
        const float t = std::clamp((glm::dot(axis, toSurfel) - cosOuter) * scale, 0.0f, 1.0f);
        att *= t * t;
    }
    return att;
}

}  // namespace

Volumes::Volumes(const LpvSettings& settings, const Inputs& inputs, const glm::dvec3& camera,
                 const glm::dvec3& viewDir, Propagation propagation)
    : settings_(settings), inputs_(inputs), propagated_(propagation == Propagation::Cpu) {
    if (!inputs.lighting || !inputs.lighting->tracer)
        throw std::invalid_argument("light propagation volumes need the terrain's tracer");
    const HeightfieldTracer& tracer = *inputs.lighting->tracer;
    for (const CascadeLayout& layout : placeCascades(settings, camera, viewDir)) {
        Cascade c;
        c.layout = layout;
        c.geometry = emptyGeometryVolume();
        c.injected = emptyLightVolume();
        buildGeometry(c, tracer.heightfield(), tracer.options().skirt);
        injectSun(c, int(cascades_.size()));
        cascades_.push_back(std::move(c));
    }
    if (inputs.lights) injectLights();
    for (Cascade& c : cascades_) {
        c.injectedFlux = totalFlux(c.injected);
        if (propagated_) propagate(c);
    }
}

void Volumes::buildGeometry(Cascade& c, const Heightfield& hf, bool skirt) const {
    // Texel (i, j, k) covers a cell-sized box centred on corner (i, j, k). Each column of texels
    // is sampled m x m times, m enough that every DEM cell is seen (at most 8).
    const double h = c.layout.cellSize;
    const double demCell = std::min(hf.cellSizeX(), hf.cellSizeZ());
    const int m = std::clamp(int(std::ceil(h / demCell)), 1, 8);
    const glm::dvec3 o = c.layout.origin();
    // Columns write only their own texels: no two iterations touch the same float.
    tbb::parallel_for(tbb::blocked_range<int>(0, kCorners * kCorners, 16), [&](const tbb::blocked_range<int>& r) {
        for (int col = r.begin(); col != r.end(); ++col) {
            const int i = col % kCorners, k = col / kCorners;
            for (int b = 0; b < m; ++b)
                for (int a = 0; a < m; ++a) {
                    const float x = float(o.x + (i - 0.5 + (a + 0.5) / m) * h);
                    const float z = float(o.z + (k - 0.5 + (b + 0.5) / m) * h);
                    if (!skirt && !hf.contains(x, z)) continue;
                    const float y = hf.surfaceHeight(x, z);
                    const glm::vec3 n = hf.surfaceNormal(x, z);
                    const float ny = std::max(n.y, 1e-3f);
                    const float area = 1.0f / float(m * m) / ny;  // / h², the patch's true area
                    // The patch rises over its width by its slope: spread it over the texels its
                    // height range crosses, in proportion.
                    const double v = (y - o.y) / h;
                    const double extent = (1.0 / m) * (std::abs(n.x) + std::abs(n.z)) / ny;
                    const double v0 = v - 0.5 * extent, v1 = v + 0.5 * extent;
                    const int j0 = std::max(0, int(std::floor(v0 + 0.5))), j1 = std::min(kCorners - 1, int(std::floor(v1 + 0.5)));
                    for (int j = j0; j <= j1; ++j) {
                        const double share = extent > 0.0
                                                 ? std::max(0.0, std::min(v1, j + 0.5) - std::max(v0, j - 0.5)) / extent
                                                 : 1.0;
                        if (share > 0.0) addBlocker(c.geometry, cornerIndex(i, j, k), n, float(area * share));
                    }
                }
        }
    });
}

void Volumes::injectSun(Cascade& c, int cascade) const {
    const BakeLighting& L = *inputs_.lighting;
    const HeightfieldTracer& tracer = *L.tracer;
    const Heightfield& hf = tracer.heightfield();
    const bool skirt = tracer.options().skirt;
    const int side = kGrid * kSurfelsPerCell;
    std::vector<Emitter> emitters(size_t(side) * side);
    if (L.sun.illuminance == glm::vec3(0.0f)) return;
    tbb::parallel_for(tbb::blocked_range<int>(0, side, 4), [&](const tbb::blocked_range<int>& r) {
        for (int row = r.begin(); row != r.end(); ++row)
            for (int colm = 0; colm < side; ++colm) {
                const int i = colm / kSurfelsPerCell, a = colm % kSurfelsPerCell;
                const int k = row / kSurfelsPerCell, b = row % kSurfelsPerCell;
                const Surfel s = surfelAt(hf, c.layout, i, k, a, b);
                if (!skirt && !s.onTerrain) continue;
                const float cosine = glm::dot(s.n, L.sun.direction);
                if (cosine <= 0.0f) continue;
                Rng rng(surfelSeed(c.layout, cascade, i, k, a, b));
                const float visible = sunVisibility(tracer, L.sun, s.p, s.n, kSunSamples, rng);
                if (visible <= 0.0f) continue;
                RayHit hit;
                hit.position = s.p;
                hit.normal = s.n;
                hit.onTerrain = s.onTerrain;
                // Reflected flux: albedo × E_sun·cos·visibility × area (Lambertian exitance × area).
                const glm::vec3 flux = L.albedoAt(hit) * L.sun.illuminance * (cosine * visible * s.area);
                const float h = float(c.layout.cellSize);
                Emitter& e = emitters[size_t(row) * side + colm];
                e.cell = cellOf(c.layout, s.p + 0.5f * h * s.n);
                e.normal = s.n;
                e.flux = flux;
            }
    });
    for (const Emitter& e : emitters) c.sunSurfels += e.cell >= 0 ? 1 : 0;
    injectAll(c.injected, emitters);
}

void Volumes::injectLights() {
    const BakeLighting& L = *inputs_.lighting;
    const HeightfieldTracer& tracer = *L.tracer;
    const Heightfield& hf = tracer.heightfield();
    const bool skirt = tracer.options().skirt;
    const std::vector<LocalLight>& lights = *inputs_.lights;
    const double fade = settings_.fadeRange;
    for (size_t li = 0; li < lights.size(); ++li) {
        const LocalLight& light = lights[li];
        LightInjection report;
        report.light = li;
        if (!settings_.localLights) {
            report.reason = "lpv.local_lights is off";
            lights_.push_back(report);
            continue;
        }
        const glm::dvec3 pos(light.position);
        // Best fit: the finest cascade whose unfaded interior holds the light's whole range; else
        // the coarsest that holds the light at all.
        int best = -1, coarsest = -1;
        for (int c = int(cascades_.size()) - 1; c >= 0; --c) {
            const CascadeLayout& lay = cascades_[size_t(c)].layout;
            if (!lay.contains(pos)) continue;
            coarsest = c;
            const glm::dvec3 lo = lay.origin() + glm::dvec3(fade * lay.cellSize);
            const glm::dvec3 hi = lay.origin() + glm::dvec3(lay.size - fade * lay.cellSize);
            bool holds = true;
            for (int a = 0; a < 3; ++a) holds = holds && pos[a] - light.range >= lo[a] && pos[a] + light.range <= hi[a];
            if (holds && best < 0) best = c;
        }
        if (best < 0) best = coarsest;
        report.cascade = best;
        if (best < 0) {
            report.reason = "outside every cascade";
            lights_.push_back(report);
            continue;
        }
        Cascade& c = cascades_[size_t(best)];
        const double h = c.layout.cellSize;
        if (light.range < h) {
            char text[160];
            std::snprintf(text, sizeof text, "range %.6g m is below cascade %d's cell (%.6g m)", light.range, best, h);
            report.reason = text;
            lights_.push_back(report);
            continue;
        }
        // The surfels of the chosen cascade within the light's range, in x and z.
        const double step = h / kSurfelsPerCell;
        const glm::dvec3 o = c.layout.origin();
        const int side = kGrid * kSurfelsPerCell;
        const int c0 = std::clamp(int(std::floor((pos.x - light.range - o.x) / step)), 0, side);
        const int c1 = std::clamp(int(std::ceil((pos.x + light.range - o.x) / step)), 0, side);
        const int r0 = std::clamp(int(std::floor((pos.z - light.range - o.z) / step)), 0, side);
        const int r1 = std::clamp(int(std::ceil((pos.z + light.range - o.z) / step)), 0, side);
        const int w = c1 - c0, d = r1 - r0;
        std::vector<Emitter> emitters(size_t(std::max(w, 0)) * size_t(std::max(d, 0)));
        const glm::vec3 emitted = light.emitted();
        tbb::parallel_for(tbb::blocked_range<int>(0, std::max(d, 0), 4), [&](const tbb::blocked_range<int>& r) {
            for (int row = r.begin(); row != r.end(); ++row)
                for (int col = 0; col < w; ++col) {
                    const int gc = c0 + col, gr = r0 + row;
                    const Surfel s = surfelAt(hf, c.layout, gc / kSurfelsPerCell, gr / kSurfelsPerCell,
                                              gc % kSurfelsPerCell, gr % kSurfelsPerCell);
                    if (!skirt && !s.onTerrain) continue;
                    const glm::vec3 toLight = light.position - s.p;
                    const float dist = glm::length(toLight);
                    if (!(dist < float(light.range)) || dist <= 0.0f) continue;
                    const glm::vec3 l = toLight / dist;
                    const float cosine = glm::dot(s.n, l);
                    if (cosine <= 0.0f) continue;
                    const float att = lightAttenuation(light, -l, dist);
                    if (att <= 0.0f) continue;
                    const glm::vec3 o2 = liftOff(s.p, s.n);
                    if (tracer.occluded(o2, glm::normalize(light.position - o2), glm::length(light.position - o2)))
                        continue;
                    RayHit hit;
                    hit.position = s.p;
                    hit.normal = s.n;
                    hit.onTerrain = s.onTerrain;
                    Emitter& e = emitters[size_t(row) * size_t(w) + size_t(col)];
                    e.cell = cellOf(c.layout, s.p + 0.5f * float(h) * s.n);
                    e.normal = s.n;
                    e.flux = L.albedoAt(hit) * emitted * (att * cosine * s.area);
                }
        });
        for (const Emitter& e : emitters) report.surfels += e.cell >= 0 ? 1 : 0;
        injectAll(c.injected, emitters);
        report.injected = true;
        lights_.push_back(report);
    }
}

float propagationStepWeight(double propagationWeight) {
    if (!(propagationWeight > 0.0)) return 0.0f;
    return float(std::pow(std::min(propagationWeight, 1.0), 1.0 / kGrid));
}

void Volumes::propagate(Cascade& c) const {
    const float weight = propagationStepWeight(settings_.propagationWeight);
    c.accumulated = c.injected;
    LightVolume current = c.injected, next;
    for (int it = 0; it < settings_.propagationIterations; ++it) {
        // The first step leaves the geometry out: the injected surfels sit half a cell above their
        // own surfaces and would shadow themselves (Kaplanyan & Dachsbacher 2010, Sec. 5.3).
        propagationStep(c.geometry, current, next, weight, it > 0);
        for (size_t i = 0; i < next.size(); ++i) c.accumulated[i] += next[i];
        current.swap(next);
    }
}

float Volumes::fadeWeight(int cascade, const glm::vec3& p) const {
    const CascadeLayout& lay = cascades_.at(size_t(cascade)).layout;
    const glm::dvec3 u = (glm::dvec3(p) - lay.origin()) / lay.cellSize;
    double dist = kGrid;
    for (int a = 0; a < 3; ++a) dist = std::min({dist, u[a], double(kGrid) - u[a]});
    if (!(dist >= 0.0)) return 0.0f;
    if (settings_.fadeRange <= 0.0) return dist > 0.0 ? 1.0f : 0.0f;
    return float(std::clamp(dist / settings_.fadeRange, 0.0, 1.0));
}

namespace {

// Trilinear weights of a point over a grid of `n` texels whose texel t sits at coordinate t.
struct Trilinear {
    std::array<int, 3> i0{};
    std::array<float, 3> t{};
};
Trilinear trilinear(const glm::dvec3& u, int n) {
    Trilinear w;
    for (int a = 0; a < 3; ++a) {
        const double v = std::clamp(u[a], 0.0, double(n - 1));
        w.i0[a] = std::min(int(v), n - 2);
        w.t[a] = float(v - w.i0[a]);
    }
    return w;
}

}  // namespace

std::array<Sh4, 3> Volumes::radianceAt(const glm::vec3& p, float* weight) const {
    if (!propagated_)
        throw std::logic_error("these light propagation volumes were left to the renderer to propagate");
    std::array<Sh4, 3> out{};
    float remaining = 1.0f;
    // Finest first: each cascade takes its fade weight of what the finer ones left.
    for (int c = int(cascades_.size()) - 1; c >= 0; --c) {
        const float w = fadeWeight(c, p) * remaining;
        if (w <= 0.0f) continue;
        const Cascade& cas = cascades_[size_t(c)];
        const double h = cas.layout.cellSize;
        const Trilinear t = trilinear((glm::dvec3(p) - cas.layout.origin()) / h - 0.5, kGrid);
        const float toRadiance = float(1.0 / (h * h));
        for (int dz = 0; dz < 2; ++dz)
            for (int dy = 0; dy < 2; ++dy)
                for (int dx = 0; dx < 2; ++dx) {
                    const float f = (dx ? t.t[0] : 1 - t.t[0]) * (dy ? t.t[1] : 1 - t.t[1]) * (dz ? t.t[2] : 1 - t.t[2]);
                    if (f == 0.0f) continue;
                    const size_t cell = cellIndex(t.i0[0] + dx, t.i0[1] + dy, t.i0[2] + dz);
                    for (int ch = 0; ch < 3; ++ch)
                        for (int k = 0; k < 4; ++k)
                            out[ch][k] += w * f * toRadiance * cas.accumulated[lightOffset(ch, cell, k)];
                }
        remaining *= 1.0f - fadeWeight(c, p);
    }
    if (weight) *weight = 1.0f - remaining;
    return out;
}

float Volumes::weightAt(const glm::vec3& p, double* cellSize) const {
    float remaining = 1.0f, best = 0.0f;
    double dominant = cascades_.empty() ? 1.0 : cascades_.front().layout.cellSize;
    for (int c = int(cascades_.size()) - 1; c >= 0; --c) {
        const float fade = fadeWeight(c, p);
        const float w = fade * remaining;
        if (w <= 0.0f) continue;
        if (w > best) best = w, dominant = cascades_[size_t(c)].layout.cellSize;
        remaining *= 1.0f - fade;
    }
    if (cellSize) *cellSize = dominant;
    return 1.0f - remaining;
}

Sh4 Volumes::geometryAt(const glm::vec3& p) const {
    Sh4 out{};
    float remaining = 1.0f;
    for (int c = int(cascades_.size()) - 1; c >= 0; --c) {
        const float w = fadeWeight(c, p) * remaining;
        if (w <= 0.0f) continue;
        const Cascade& cas = cascades_[size_t(c)];
        const Trilinear t = trilinear((glm::dvec3(p) - cas.layout.origin()) / cas.layout.cellSize, kCorners);
        for (int dz = 0; dz < 2; ++dz)
            for (int dy = 0; dy < 2; ++dy)
                for (int dx = 0; dx < 2; ++dx) {
                    const float f = (dx ? t.t[0] : 1 - t.t[0]) * (dy ? t.t[1] : 1 - t.t[1]) * (dz ? t.t[2] : 1 - t.t[2]);
                    const size_t corner = cornerIndex(t.i0[0] + dx, t.i0[1] + dy, t.i0[2] + dz);
                    for (int k = 0; k < 4; ++k) out[k] += w * f * cas.geometry[corner * 4 + k];
                }
        remaining *= 1.0f - fadeWeight(c, p);
    }
    return out;
}

glm::vec3 Volumes::irradianceAt(const glm::vec3& q, const glm::vec3& n, int quality) const {
    const std::array<Sh4, 3> l = radianceAt(q);
    // The volume holds light by the way it flows: what arrives at a surface facing n flows along −n.
    glm::vec3 e;
    if (quality == 0)
        for (int ch = 0; ch < 3; ++ch) e[ch] = irradianceLinear(l[ch], -n);
    else
        e = irradianceZh3Hallucinated(l, -n);
    return glm::max(e, glm::vec3(0.0f));
}

Sample Volumes::evaluate(const glm::vec3& p, const glm::vec3& n, const glm::vec3& toEye, int quality) const {
    if (!propagated_)
        throw std::logic_error("these light propagation volumes were left to the renderer to propagate");
    Sample out;
    double h = 1.0;
    if (weightAt(p, &h) <= 0.0f) return out;
    // Half a cell out along the normal, as the paper samples, so a surface does not read the
    // light its own cell holds behind it.
    const float half = float(0.5 * h);
    const glm::vec3 q = p + half * n;
    glm::vec3 e = irradianceAt(q, n, quality);
    if (quality >= 1) {
        // Leak dampening by the directional derivative along the normal: where the irradiance
        // grows into the surface, the light came through it from behind (a coarse cell straddling
        // a ridge); damp it by how much: × clamp(1 + min(0, E(q + h/2·n) − E(q − h/2·n)) / E(q), 0, 1).
        const float front = glsl::rec709Luminance(irradianceAt(q + half * n, n, quality));
        const float back = glsl::rec709Luminance(irradianceAt(q - half * n, n, quality));
        const float centre = glsl::rec709Luminance(e);
        if (centre > 0.0f) e *= std::clamp(1.0f + std::min(0.0f, front - back) / centre, 0.0f, 1.0f);
    }
    if (quality >= 2) {
        // Cone-traced specular: the radiance flowing back toward the surface along the mirror
        // direction, sampled every cell (the blended cascades coarsen with distance from the
        // camera), each sample dimmed by the geometry it had to pass, averaged.
        const glm::vec3 r = reflectDir(-toEye, n);
        glm::vec3 sum(0.0f);
        float transmit = 1.0f;
        const int samples = std::max(settings_.coneTraceSamples, 1);
        for (int i = 0; i < samples; ++i) {
            const glm::vec3 x = q + float((i + 1) * h) * r;
            const std::array<Sh4, 3> l = radianceAt(x);
            for (int ch = 0; ch < 3; ++ch) sum[ch] += transmit * std::max(0.0f, lpv::evaluate(l[ch], -r));
            transmit *= 1.0f - blocking(geometryAt(x), -r);
        }
        out.specular = sum / float(samples) * float(settings_.indirectIntensity);
    }
    out.irradiance = e * float(settings_.indirectIntensity);
    return out;
}

double Volumes::blendedCellSize(const glm::vec3& p) const {
    float remaining = 1.0f;
    double sum = 0.0;
    for (int c = int(cascades_.size()) - 1; c >= 0; --c) {
        const float fade = fadeWeight(c, p);
        const float w = fade * remaining;
        if (w <= 0.0f) continue;
        sum += w * cascades_[size_t(c)].layout.cellSize;
        remaining *= 1.0f - fade;
    }
    const float total = 1.0f - remaining;
    return total > 0.0f ? sum / total : 0.0;
}

float Volumes::ambientOcclusion(const glm::vec3& p, const glm::vec3& n) const {
    double h = 1.0;
    if (weightAt(p, &h) <= 0.0f) return 1.0f;
    const glm::vec3 q = p + float(0.5 * h) * n;
    float open = 0.0f;
    for (int k = 0; k < kAoDirections; ++k) {
        const glm::vec3 w = cosineHemisphere(uint32_t(k), uint32_t(kAoDirections), 0.0f, n);
        // Each step samples the middle of a stretch one cell long, so a texel's blocking (the share
        // of a cell's cross-section its surfaces cover) is counted once per cell crossed.
        float transmit = 1.0f;
        float t = 0.0f;
        for (int j = 0; j < kAoSteps && transmit > kAoCutoff; ++j) {
            const float hx = float(blendedCellSize(q + t * w));
            if (hx <= 0.0f) break;
            const glm::vec3 x = q + (t + 0.5f * hx) * w;
            // What p sees along w: the surfaces facing back toward it (blocking light flowing along w).
            transmit *= 1.0f - blocking(geometryAt(x), w);
            t += hx;
        }
        open += transmit;
    }
    return open / float(kAoDirections);
}

GroundComparison compareWithOneBounce(const Volumes& volumes, const BakeLighting& lighting,
                                      const std::vector<glm::vec2>& points, int cacheResolution, int cacheRays) {
    // The LPV carries the sun's first bounce only: the reference gets a black sky.
    BakeLighting sunOnly = lighting;
    sunOnly.sky = Sky::uniform(glm::vec3(0.0f));
    const IrradianceCache cache(sunOnly, cacheResolution, cacheRays, kSunSamples, 1, BakeControl{});
    const Heightfield& hf = lighting.tracer->heightfield();
    GroundComparison out;
    double sq = 0, refSq = 0;
    for (const glm::vec2& xz : points) {
        const glm::vec3 p(xz.x, hf.surfaceHeight(xz.x, xz.y), xz.y);
        const glm::vec3 n = hf.surfaceNormal(xz.x, xz.y);
        RayHit hit;
        hit.position = p;
        hit.normal = n;
        hit.onTerrain = hf.contains(xz.x, xz.y);
        out.positions.push_back(p);
        out.normals.push_back(n);
        out.lpv.push_back(volumes.evaluate(p, n, n).irradiance);
        out.reference.push_back(cache.indirectAt(hit));
        const double a = glsl::rec709Luminance(out.lpv.back()), b = glsl::rec709Luminance(out.reference.back());
        out.meanLpv += a;
        out.meanReference += b;
        sq += (a - b) * (a - b);
        refSq += b * b;
    }
    if (!points.empty()) {
        out.meanLpv /= double(points.size());
        out.meanReference /= double(points.size());
        out.relativeRms = refSq > 0 ? std::sqrt(sq / refSq) : 0.0;
    }
    return out;
}

}  // namespace terralux::lpv
