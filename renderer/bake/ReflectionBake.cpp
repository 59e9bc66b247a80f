#include "bake/ReflectionBake.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <numbers>
#include <sstream>

#include <glm/geometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "ShaderMath.h"
#include "bake/SphereSampling.h"

namespace terralux {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

std::string num(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

// Runs body(i) for i in [0, n) in parallel chunks with progress and cancel; results go to
// per-index slots, so the chunking changes no value.
template <typename Body>
void parallelIndices(size_t n, const BakeControl& control, Body body) {
    std::atomic<size_t> done{0};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1), [&](const tbb::blocked_range<size_t>& r) {
        if (control.cancelled()) return;
        for (size_t i = r.begin(); i != r.end(); ++i) body(i);
        const size_t d = done.fetch_add(r.size()) + r.size();
        if (control.progress) control.progress(double(d) / double(std::max<size_t>(n, 1)));
    });
    if (control.cancelled()) throw BakeCancelled();
}

// The area-element integral of a cube face from its centre to (x, y) in face coordinates [-1, 1]
// (the solid angle of a face rectangle is a signed sum of four of them).
double areaElement(double x, double y) { return std::atan2(x * y, std::sqrt(x * x + y * y + 1.0)); }

// GGX normal distribution D(h) with α = roughness² (Walter et al., "Microfacet Models for
// Refraction through Rough Surfaces", EGSR 2007) is α² / (π ((n·h)² (α² − 1) + 1)²); the
// prefilter's normalised weights need it only up to its constant.

// Unit texel-centre directions and solid angles of a face `size` a side, all six faces.
struct CubeGeometry {
    std::vector<glm::vec3> dir;
    std::vector<float> solidAngle;
    explicit CubeGeometry(int size) {
        dir.reserve(size_t(6) * size * size);
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < size; ++y)
                for (int x = 0; x < size; ++x) {
                    dir.push_back(cubeDirection(f, (float(x) + 0.5f) / float(size), (float(y) + 0.5f) / float(size)));
                    solidAngle.push_back(cubeTexelSolidAngle(size, x, y));
                }
    }
};

// ∫ L(l) D(h)(n·l) dl / ∫ D(h)(n·l) dl over the texels of one level, for n = v = `dir`.
glm::vec3 ggxIntegral(const std::vector<glm::vec3>& texels, const CubeGeometry& g, const glm::vec3& n,
                      float roughness) {
    const double a = std::max(double(roughness) * roughness, 1e-4), a2 = a * a;
    glm::dvec3 sum(0.0);
    double weight = 0.0;
    for (size_t i = 0; i < texels.size(); ++i) {
        const glm::vec3& l = g.dir[i];
        const float ndotl = glm::dot(n, l);
        if (ndotl <= 0.0f) continue;
        // h = normalize(n + l): n·h² = (1 + n·l) / 2 for unit n and l; D up to its constant 1/π.
        const double d = 0.5 * (1.0 + double(ndotl)) * (a2 - 1.0) + 1.0;
        const double w = double(ndotl) * double(g.solidAngle[i]) / (d * d);
        sum += w * glm::dvec3(texels[i]);
        weight += w;
    }
    return weight > 0.0 ? glm::vec3(sum / weight) : glm::vec3(0.0f);
}

// Solid-angle-weighted 2×2 reduction of a cube level.
std::vector<glm::vec3> halve(const std::vector<glm::vec3>& texels, int size) {
    const int h = std::max(size / 2, 1);
    std::vector<glm::vec3> out(size_t(6) * h * h);
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < h; ++x) {
                glm::dvec3 sum(0.0);
                double w = 0.0;
                for (int dy = 0; dy < 2; ++dy)
                    for (int dx = 0; dx < 2; ++dx) {
                        const int sx = std::min(2 * x + dx, size - 1), sy = std::min(2 * y + dy, size - 1);
                        const double a = cubeTexelSolidAngle(size, sx, sy);
                        sum += a * glm::dvec3(texels[(size_t(f) * size + sy) * size + sx]);
                        w += a;
                    }
                out[(size_t(f) * h + y) * h + x] = glm::vec3(sum / w);
            }
    return out;
}

// Seamless bilinear lookup in one level (`base` its first texel, `size` a side) around (s, t) on
// `face`, as cube-map hardware filters across face edges (Vulkan spec, "Cube Map Edge Handling"):
// a tap past the edge reads the texel of the neighbouring face its direction falls on.
glm::vec3 bilinear(const std::vector<glm::vec3>& texels, size_t base, int size, int face, float s, float t) {
    const float fx = s * float(size) - 0.5f, fy = t * float(size) - 0.5f;
    const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
    const float ax = fx - float(x0), ay = fy - float(y0);
    auto at = [&](int x, int y) {
        int f = face;
        if (x < 0 || y < 0 || x >= size || y >= size) {
            float s2, t2;
            f = cubeFace(cubeDirection(face, (float(x) + 0.5f) / float(size), (float(y) + 0.5f) / float(size)), s2, t2);
            x = std::clamp(int(s2 * float(size)), 0, size - 1);
            y = std::clamp(int(t2 * float(size)), 0, size - 1);
        }
        return texels[base + (size_t(f) * size + size_t(y)) * size + size_t(x)];
    };
    return (1.0f - ay) * ((1.0f - ax) * at(x0, y0) + ax * at(x0 + 1, y0)) +
           ay * ((1.0f - ax) * at(x0, y0 + 1) + ax * at(x0 + 1, y0 + 1));
}

const std::vector<glm::vec3>& errorDirections() {
    static const std::vector<glm::vec3> d = [] {
        std::vector<glm::vec3> v;
        for (uint32_t i = 0; i < 256; ++i) v.push_back(fibonacciSphere(i, 256, 0.0f));
        return v;
    }();
    return d;
}

}  // namespace

glm::vec3 ReflectionLayout::halfExtent(size_t i) const {
    const float cell = std::max(cellSize.x, cellSize.y);
    return glm::vec3(0.5f * cellSize.x, 0.5f * (positions[i].y + cell - lowestBelow[i]), 0.5f * cellSize.y);
}

ReflectionLayout placeReflectionProbes(const ReflectionProbeSettings& s, const Heightfield& hf) {
    const std::string at = "reflection_probes.";
    const int nx = s.gridDims[0], nz = s.gridDims[1];
    if (nx < 1 || nz < 1 || int64_t(nx) * int64_t(nz) > kMaxReflectionProbes)
        throw PlacementError(at + "grid_dims = [" + std::to_string(nx) + "," + std::to_string(nz) +
                             "]: must be >= 1 each with a product <= " + std::to_string(kMaxReflectionProbes) +
                             " (is " + std::to_string(int64_t(nx) * int64_t(nz)) + ")");
    if (!(s.strength >= 0.0 && s.strength <= 1.0))
        throw PlacementError(at + "strength = " + num(s.strength) + ": must be in [0, 1]");
    if (s.spacing && !(s.spacing->x > 0.0f && s.spacing->y > 0.0f && std::isfinite(s.spacing->x) &&
                       std::isfinite(s.spacing->y)))
        throw PlacementError(at + "spacing = [" + num(s.spacing->x) + "," + num(s.spacing->y) +
                             "]: must be > 0 each");
    if (s.fallbackBlendDistance && !(*s.fallbackBlendDistance >= 0.0))
        throw PlacementError(at + "fallback_blend_distance = " + num(*s.fallbackBlendDistance) + ": must be >= 0");
    if (!(s.rayCount >= 1)) throw PlacementError(at + "ray_count = " + std::to_string(s.rayCount) + ": must be >= 1");
    if (s.resolution < 8 || s.resolution > 128 || !std::has_single_bit(unsigned(s.resolution)))
        throw PlacementError(at + "resolution = " + std::to_string(s.resolution) +
                             ": must be a power of two in [8, 128]");

    ReflectionLayout L;
    L.dims = {nx, nz};
    const float spanX = hf.maxX() - hf.minX(), spanZ = hf.maxZ() - hf.minZ();
    if (s.spacing) {
        L.spacing = *s.spacing;
        if (nx == 1) L.spacing.x = 0.0f;
        if (nz == 1) L.spacing.y = 0.0f;
    } else {
        L.spacing = glm::vec2(nx > 1 ? spanX / float(nx - 1) : 0.0f, nz > 1 ? spanZ / float(nz - 1) : 0.0f);
    }
    // Centred on the footprint unless placed: auto-span puts the end probes on its edges, a
    // one-probe axis sits at its centre (seed 000's terrain-grid rule).
    L.origin = s.origin ? *s.origin
                        : glm::vec2(0.5f * (hf.minX() + hf.maxX()) - 0.5f * L.spacing.x * float(nx - 1),
                                    0.5f * (hf.minZ() + hf.maxZ()) - 0.5f * L.spacing.y * float(nz - 1));
    // A probe's cell: its share of the grid, or the footprint's extent along a one-probe axis.
    L.cellSize = glm::vec2(nx > 1 ? L.spacing.x : spanX, nz > 1 ? L.spacing.y : spanZ);
    if (!(L.cellSize.x > 0.0f)) L.cellSize.x = std::max(float(hf.cellSizeX()), 1.0f);
    if (!(L.cellSize.y > 0.0f)) L.cellSize.y = std::max(float(hf.cellSizeZ()), 1.0f);
    for (int k = 0; k < nz; ++k)
        for (int i = 0; i < nx; ++i) {
            const float x = L.origin.x + L.spacing.x * float(i), z = L.origin.y + L.spacing.y * float(k);
            const float ground = hf.surfaceHeight(x, z);
            glm::vec3 p(x, ground + float(s.heightOffset), z);
            if (s.heightOffset > 0.0 && !(p.y > ground)) p.y = std::nextafter(ground, INFINITY);
            L.positions.push_back(p);
            const SurfaceRange r = surfaceRange(hf, x - 0.5 * L.cellSize.x, x + 0.5 * L.cellSize.x,
                                                z - 0.5 * L.cellSize.y, z + 0.5 * L.cellSize.y);
            L.lowestBelow.push_back(std::min(std::isfinite(r.lo) ? r.lo : ground, p.y));
        }
    // The cell of a one-probe axis is the footprint's extent along it: the width that probe covers.
    L.blendDistance = s.fallbackBlendDistance ? float(*s.fallbackBlendDistance)
                                              : defaultFallbackBlendDistance(L.spacing, L.cellSize);
    return L;
}

int cubeMipCount(int size) {
    return std::max(1, int(std::bit_width(unsigned(std::max(size, 1)))) - int(std::bit_width(unsigned(kSmallestCubeMip))) + 1);
}

float cubeMipRoughness(int level, int count) { return count > 1 ? float(level) / float(count - 1) : 0.0f; }

glm::vec3 cubeDirection(int face, float s, float t) {
    const float u = 2.0f * s - 1.0f, v = 2.0f * t - 1.0f;
    glm::vec3 d;
    switch (face) {
        case 0: d = {1.0f, -v, -u}; break;
        case 1: d = {-1.0f, -v, u}; break;
        case 2: d = {u, 1.0f, v}; break;
        case 3: d = {u, -1.0f, -v}; break;
        case 4: d = {u, -v, 1.0f}; break;
        default: d = {-u, -v, -1.0f}; break;
    }
    return glm::normalize(d);
}

int cubeFace(const glm::vec3& d, float& s, float& t) {
    const float ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
    int face;
    float sc, tc, ma;
    // Vulkan spec, "Cube Map Face Selection": the major axis picks the face, ties to x, then y.
    if (ax >= ay && ax >= az) {
        face = d.x >= 0.0f ? 0 : 1;
        ma = ax;
        sc = d.x >= 0.0f ? -d.z : d.z;
        tc = -d.y;
    } else if (ay >= az) {
        face = d.y >= 0.0f ? 2 : 3;
        ma = ay;
        sc = d.x;
        tc = d.y >= 0.0f ? d.z : -d.z;
    } else {
        face = d.z >= 0.0f ? 4 : 5;
        ma = az;
        sc = d.z >= 0.0f ? d.x : -d.x;
        tc = -d.y;
    }
    ma = std::max(ma, 1e-30f);
    s = 0.5f * (sc / ma + 1.0f);
    t = 0.5f * (tc / ma + 1.0f);
    return face;
}

float cubeTexelSolidAngle(int size, int x, int y) {
    const double x0 = 2.0 * x / size - 1.0, x1 = 2.0 * (x + 1) / size - 1.0;
    const double y0 = 2.0 * y / size - 1.0, y1 = 2.0 * (y + 1) / size - 1.0;
    return float(areaElement(x0, y0) - areaElement(x0, y1) - areaElement(x1, y0) + areaElement(x1, y1));
}

size_t ReflectionProbeSet::texelsPerProbe() const {
    if (encoding != ReflectionEncoding::Cubemap) return 0;
    size_t n = 0;
    for (int m = 0; m < mipCount; ++m) n += size_t(6) * size_t(cubeMipSize(faceSize, m)) * size_t(cubeMipSize(faceSize, m));
    return n;
}

size_t ReflectionProbeSet::texelOffset(int level, int face) const {
    size_t n = 0;
    for (int m = 0; m < level; ++m) n += size_t(6) * size_t(cubeMipSize(faceSize, m)) * size_t(cubeMipSize(faceSize, m));
    const size_t side = size_t(cubeMipSize(faceSize, level));
    return n + size_t(face) * side * side;
}

glm::vec3 ReflectionProbeSet::evaluate(size_t i, const glm::vec3& dir, float roughness) const {
    const ReflectionProbe& p = probes[i];
    if (encoding == ReflectionEncoding::Faces || p.texels.empty()) {
        // The ambient cube (McTaggart, "Half-Life 2 / Valve Source Shading", GDC 2004): the
        // squared components of a unit direction sum to one.
        const glm::vec3 d2 = dir * dir / std::max(glm::dot(dir, dir), 1e-30f);
        return d2.x * p.faces[dir.x >= 0.0f ? 0 : 1] + d2.y * p.faces[dir.y >= 0.0f ? 2 : 3] +
               d2.z * p.faces[dir.z >= 0.0f ? 4 : 5];
    }
    float s, t;
    const int face = cubeFace(dir, s, t);
    const float lod = std::clamp(roughness, 0.0f, 1.0f) * float(mipCount - 1);
    const int m0 = std::min(int(lod), mipCount - 1), m1 = std::min(m0 + 1, mipCount - 1);
    const float f = lod - float(m0);
    const glm::vec3 a = bilinear(p.texels, texelOffset(m0, 0), cubeMipSize(faceSize, m0), face, s, t);
    if (f <= 0.0f || m1 == m0) return a;
    const glm::vec3 b = bilinear(p.texels, texelOffset(m1, 0), cubeMipSize(faceSize, m1), face, s, t);
    return (1.0f - f) * a + f * b;
}

glm::vec3 groundRadiance(const BakeLighting& L, const glm::vec3& color) {
    return color / kPi * (L.sky.openIrradianceUp() + L.sun.illuminance * std::max(0.0f, L.sun.direction.y));
}

RadianceCube traceRadianceCube(const ReflectionLighting& light, const glm::vec3& position, int size,
                               int raysPerTexel, uint64_t seed, uint64_t* rays) {
    RadianceCube cube;
    cube.size = size;
    cube.texels.resize(size_t(6) * size * size);
    raysPerTexel = std::max(raysPerTexel, 1);
    const BakeLighting& L = *light.lighting;
    const int bounces = std::max(light.bounces, 1);
    // R2 sequence (Roberts 2018, "The Unreasonable Effectiveness of Quasirandom Sequences"): the
    // rays of a texel cover it evenly; a per-texel offset decorrelates neighbours.
    constexpr double kA1 = 0.7548776662466927, kA2 = 0.5698402909980532;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x) {
                const uint64_t key = splitmix64(seed ^ (uint64_t(f) << 48 | uint64_t(y) << 24 | uint64_t(x)));
                Rng rng(key);
                const double o1 = hashToUnit(splitmix64(key + 1)), o2 = hashToUnit(splitmix64(key + 2));
                const float texelAngle = cubeTexelSolidAngle(size, x, y);
                glm::dvec3 sum(0.0);
                double wsum = 0.0;
                for (int k = 0; k < raysPerTexel; ++k) {
                    double j1 = o1 + kA1 * k, j2 = o2 + kA2 * k;
                    j1 -= std::floor(j1);
                    j2 -= std::floor(j2);
                    const float s = (float(x) + float(j1)) / float(size), t = (float(y) + float(j2)) / float(size);
                    const float u = 2.0f * s - 1.0f, v = 2.0f * t - 1.0f;
                    const glm::vec3 d = cubeDirection(f, s, t);
                    // Uniform in (s, t) is not uniform in solid angle: weight by dω/dA.
                    const double w = std::pow(1.0 + double(u) * u + double(v) * v, -1.5);
                    sum += w * glm::dvec3(probeRayRadiance(L, light.cache, bounces, position, d, texelAngle, rng,
                                                           &light.ground));
                    wsum += w;
                }
                cube.at(f, x, y) = glm::vec3(sum / wsum);
            }
    if (rays) *rays = uint64_t(6) * size * size * raysPerTexel;
    return cube;
}

std::array<glm::vec3, 6> faceMeans(const RadianceCube& cube) {
    std::array<glm::vec3, 6> out{};
    for (int f = 0; f < 6; ++f) {
        glm::dvec3 sum(0.0);
        double w = 0.0;
        for (int y = 0; y < cube.size; ++y)
            for (int x = 0; x < cube.size; ++x) {
                const double a = cubeTexelSolidAngle(cube.size, x, y);
                sum += a * glm::dvec3(cube.at(f, x, y));
                w += a;
            }
        out[size_t(f)] = glm::vec3(sum / w);
    }
    return out;
}

std::vector<glm::vec3> prefilterCube(const RadianceCube& cube) {
    const int count = cubeMipCount(cube.size);
    std::vector<glm::vec3> out = cube.texels;
    // The unfiltered radiance at each level's resolution: mip m integrates level m of it (its own
    // resolution, never a filtered level filtered again). A lobe narrower than that level's
    // texels is a texel the mip cannot hold finer anyway.
    std::vector<glm::vec3> source = cube.texels;
    int sourceSize = cube.size;
    for (int m = 1; m < count; ++m) {
        source = halve(source, sourceSize);
        sourceSize = std::max(sourceSize / 2, 1);
        const CubeGeometry g(sourceSize);
        const int size = cubeMipSize(cube.size, m);
        const float roughness = cubeMipRoughness(m, count);
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < size; ++y)
                for (int x = 0; x < size; ++x)
                    out.push_back(ggxIntegral(source, g, cubeDirection(f, (x + 0.5f) / size, (y + 0.5f) / size),
                                              roughness));
    }
    return out;
}

glm::vec3 prefilteredRadiance(const RadianceCube& cube, const glm::vec3& dir, float roughness) {
    const CubeGeometry g(cube.size);
    return ggxIntegral(cube.texels, g, glm::normalize(dir), roughness);
}

ReflectionProbeSet bakeReflectionProbes(const ReflectionLighting& light, const ReflectionProbeSettings& settings,
                                        const ReflectionLayout& layout, uint64_t seed,
                                        const BakeControl& control, uint64_t* rays,
                                        std::vector<RadianceCube>* cubes) {
    ReflectionProbeSet set;
    set.encoding = ReflectionEncoding::Cubemap;
    set.faceSize = settings.resolution;
    set.mipCount = cubeMipCount(settings.resolution);
    set.dims = layout.dims;
    set.origin = layout.origin;
    set.spacing = layout.spacing;
    set.cellSize = layout.cellSize;
    set.strength = float(settings.strength);
    set.blendDistance = layout.blendDistance;
    set.probes.resize(layout.count());
    if (cubes) cubes->assign(layout.count(), {});
    std::vector<uint64_t> traced(layout.count(), 0);
    parallelIndices(layout.count(), control, [&](size_t i) {
        ReflectionProbe& p = set.probes[i];
        p.id = uint32_t(i);
        p.position = layout.positions[i];
        p.halfExtent = layout.halfExtent(i);
        RadianceCube cube = traceRadianceCube(light, p.position, settings.resolution, settings.rayCount,
                                              splitmix64(seed + i), &traced[i]);
        p.faces = faceMeans(cube);
        p.texels = prefilterCube(cube);
        if (cubes) (*cubes)[i] = std::move(cube);
    });
    if (rays) {
        *rays = 0;
        for (uint64_t t : traced) *rays += t;
    }
    return set;
}

void toEncoding(ReflectionProbeSet& set, ReflectionEncoding encoding) {
    set.encoding = encoding;
    if (encoding == ReflectionEncoding::Faces) {
        set.faceSize = 0;
        set.mipCount = 1;
        for (auto& p : set.probes) {
            p.texels.clear();
            p.texels.shrink_to_fit();
        }
    }
}

// The reference's prefiltered luminance toward each of the 256 directions.
std::vector<double> referenceLuminance(const RadianceCube& reference, float roughness) {
    const CubeGeometry g(reference.size);
    std::vector<double> out;
    for (const glm::vec3& d : errorDirections()) out.push_back(glsl::rec709Luminance(ggxIntegral(reference.texels, g, d, roughness)));
    return out;
}

float reflectionProbeError(const ReflectionProbeSet& set, size_t probe, ReflectionEncoding encoding,
                           const std::vector<double>& reference, float roughness) {
    ReflectionProbeSet view;
    const ReflectionProbeSet* s = &set;
    if (encoding != set.encoding) {
        // Read a cubemap set's face colours as a faces set would.
        view.encoding = ReflectionEncoding::Faces;
        view.probes = {set.probes[probe]};
        view.probes[0].texels.clear();
        s = &view;
        probe = 0;
    }
    double num = 0, den = 0;
    const auto& dirs = errorDirections();
    for (size_t k = 0; k < dirs.size(); ++k) {
        const double e = glsl::rec709Luminance(s->evaluate(probe, dirs[k], roughness));
        num += (e - reference[k]) * (e - reference[k]);
        den += reference[k] * reference[k];
    }
    return den > 0 ? float(std::sqrt(num / den)) : 0.0f;
}

float reflectionProbeError(const ReflectionProbeSet& set, size_t probe, ReflectionEncoding encoding,
                           const RadianceCube& reference, float roughness) {
    return reflectionProbeError(set, probe, encoding, referenceLuminance(reference, roughness), roughness);
}

ReflectionErrorReport measureReflectionError(const ReflectionLighting& light,
                                             const ReflectionProbeSettings& settings,
                                             const ReflectionProbeSet& set,
                                             const std::vector<float>& roughnesses, uint64_t seed,
                                             const BakeControl& control) {
    ReflectionErrorReport out;
    out.referenceResolution = 4 * settings.resolution;
    const size_t n = set.probes.size(), nr = roughnesses.size();
    std::vector<float> faces(n * nr), cubemap(n * nr);
    std::vector<uint64_t> traced(n, 0);
    parallelIndices(n, control, [&](size_t i) {
        const RadianceCube ref = traceRadianceCube(light, set.probes[i].position, out.referenceResolution,
                                                   settings.rayCount, splitmix64(seed ^ 0x5EF1EC7ull) + i, &traced[i]);
        for (size_t r = 0; r < nr; ++r) {
            const std::vector<double> truth = referenceLuminance(ref, roughnesses[r]);
            faces[i * nr + r] = reflectionProbeError(set, i, ReflectionEncoding::Faces, truth, roughnesses[r]);
            cubemap[i * nr + r] = reflectionProbeError(set, i, ReflectionEncoding::Cubemap, truth, roughnesses[r]);
        }
    });
    for (size_t r = 0; r < nr; ++r) {
        std::vector<float> f, c;
        for (size_t i = 0; i < n; ++i) {
            f.push_back(faces[i * nr + r]);
            c.push_back(cubemap[i * nr + r]);
        }
        out.byRoughness.push_back({roughnesses[r], spreadOf(f), spreadOf(c)});
    }
    for (uint64_t t : traced) out.rays += t;
    return out;
}

}  // namespace terralux
