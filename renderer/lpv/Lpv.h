#pragma once
// Light propagation volumes on the CPU (docs/lighting.md, "Light propagation volumes"): the
// engine-independent core; the renderer's shaders/lpv.glsl mirrors evaluate(). After Kaplanyan &
// Dachsbacher, "Cascaded Light Propagation Volumes for Real-Time Indirect Illumination" (I3D 2010):
//
//   1. cascades: 1-4 volumes of 32^3 cells ahead of the camera, each snapped to its own cells;
//   2. geometry volume: the heightfield's surfaces as L1 SH blocking potential, on the light
//      volume's cell corners (the paper's half-cell offset);
//   3. injection: sunlit terrain surfels (a reflective shadow map made from the heightfield, sun
//      visibility from the bake's tracer) and point and spot lights, each a clamped-cosine lobe of
//      its reflected flux, half a cell along its normal;
//   4. propagation: six-neighbour, five-face transfer, scaled per step by w^(1/32) for the
//      propagation weight w (propagationStepWeight), blocked by the geometry volume, accumulated
//      over the iterations; here, or by the renderer's compute pass (shaders/lpv_propagate.comp,
//      Propagation::Renderer), which takes propagationStep's operations in the same order;
//   5. apply: irradiance at a point and normal (linear L1, or ZH3 with leak dampening), cone-traced
//      specular at quality 2, and (view 63 only) an ambient occlusion marched through the geometry
//      volume.
//
// Memory layout, as the renderer uploads it (a storage buffer per array, cascades one after
// another; as 3-D images it would be one per array), x fastest:
//   light volume    3 x RGBA32F 32^3 per cascade: float[channel][cell][4], channel R, G, B,
//                   cell = x + 32·(y + 32·z), the 4 values the L1 SH coefficients k = 0..3 of the
//                   cell's intensity I(ω) in W/sr (SphericalHarmonics.h's order: 1, y, z, x)
//   geometry volume 1 x RGBA32F 33^3 per cascade: float[corner][4], corner = x + 33·(y + 33·z),
//                   texel (x, y, z) centred on the light volume's cell corner (x, y, z); 33 so
//                   every face between two cells has its four corners
// "Intensity" is the paper's: the cell radiates like a point light; its radiance is I / h^2 for
// cell size h. Everything is deterministic: parallel loops write per-index slots, and sums over
// scattered contributions run in a fixed order, so any thread count gives the same bits.

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "bake/DiffuseBake.h"
#include "scene/SceneDescription.h"
#include "terrain/Heightfield.h"

namespace terralux::lpv {

inline constexpr int kGrid = 32;                                 // cells a side
inline constexpr int kCells = kGrid * kGrid * kGrid;
inline constexpr int kCorners = kGrid + 1;                       // geometry texels a side
inline constexpr int kCornerCount = kCorners * kCorners * kCorners;
// Reflective-shadow-map texels (surfels) per cell side in x and z: 4 x 4 per cell column, a
// 128^2 map per cascade.
inline constexpr int kSurfelsPerCell = 4;
// Shadow rays per surfel across the sun's disc.
inline constexpr int kSunSamples = 4;
// The geometry volume's ambient occlusion: cosine-weighted directions, and the most steps along
// each (a step is the blended cell; 48 cross a cascade's diagonal from its centre, and the march
// ends sooner where it leaves the volumes or the light left is below kAoCutoff).
inline constexpr int kAoDirections = 16;
inline constexpr int kAoSteps = 48;
inline constexpr float kAoCutoff = 1e-3f;

// ---- L1 spherical harmonics (the 4 coefficients of SphericalHarmonics.h's first two bands) --

using Sh4 = std::array<float, 4>;
Sh4 basis(const glm::vec3& dir);
float evaluate(const Sh4& sh, const glm::vec3& dir);
// Projection of scale·max(0, n·ω): Â_l·Y_k(n)·scale with Â = {π, 2π/3} (Ramamoorthi & Hanrahan 2001).
Sh4 clampedCosine(const glm::vec3& n, float scale);
// Irradiance on a surface with normal n from radiance SH `l` (light arriving from ω, L(ω)):
// Σ Â_l L_k Y_k(n), the linear (L1) reconstruction.
float irradianceLinear(const Sh4& l, const glm::vec3& n);
// Irradiance from an L1 radiance plus one zonal L2 coefficient `z2` about unit `axis` (a ZH3
// function, Roughton et al., "ZH3: Quadratic Zonal Harmonics", I3D 2024): the linear part +
// (π/4)·z2·Y_20(axis·n), Y_20(t) = √(5/16π)(3t² − 1). Exact for any zonal function about `axis`
// whose band-2 part is z2.
float irradianceZh3(const Sh4& l, float z2, const glm::vec3& axis, const glm::vec3& n);
// ZH3 hallucinated from L1 alone, RGB sharing the luminance's axis (their Section 3.4.3): axis =
// the luminance-weighted L1 direction, r = |L1_c · axis| / L0_c per channel, z2 = L0_c·(0.08 r + 0.6 r²).
glm::vec3 irradianceZh3Hallucinated(const std::array<Sh4, 3>& rgb, const glm::vec3& n);
// The zonal coefficient that fit gives for one channel whose L1 direction is `axis`.
float hallucinatedZonal(const Sh4& l, const glm::vec3& axis);

// ---- Cascades -----------------------------------------------------------------------------------

// lpv.size left null: cascade 0 spans the terrain footprint's longer side, so the coarsest cascade
// can hold the whole terrain whatever its size (a fixed default held 7 % of an 80 km tile's width
// and left the LPV views nearly black), and at least 32 DEM cells, one per LPV cell; at most 1e6 m.
double autoSize(const Heightfield& terrain);
// The settings with `size` resolved on `terrain` (kept when set). Everything below reads a
// resolved size and throws std::logic_error on an unresolved one.
LpvSettings resolvedOn(LpvSettings settings, const Heightfield& terrain);
double sizeOf(const LpvSettings& s);

// The size ratio between consecutive cascades: cascade_ratio, raised with auto_cascade_min_size
// > 0 (and two or more cascades) to (size / min)^(1/(cascades − 1)) when that is larger, so the
// smallest cascade is at most the minimum size (exactly it when the rule raised the ratio).
double cascadeRatio(const LpvSettings& s);
// Edge of each cascade, metres: size / ratio^i.
std::vector<double> cascadeSizes(const LpvSettings& s);

struct CascadeLayout {
    double size = 0.0;      // edge, metres
    double cellSize = 0.0;  // size / 32
    glm::dvec3 wanted{0.0}; // the unsnapped centre: camera + forward_offset·size·view
    // Min corner in whole cells from the engine origin: floor(wanted / cellSize) − 16, so the
    // volume moves only in steps of its own cells and lighting does not swim.
    std::array<long long, 3> originCell{};
    glm::dvec3 origin() const;  // originCell · cellSize
    glm::dvec3 centre() const;  // origin + size / 2
    bool contains(const glm::dvec3& p) const;
};
std::vector<CascadeLayout> placeCascades(const LpvSettings& s, const glm::dvec3& camera,
                                         const glm::dvec3& viewDir);

// ---- Volumes and propagation --------------------------------------------------------------------

inline size_t cellIndex(int x, int y, int z) { return size_t(x) + kGrid * (size_t(y) + kGrid * size_t(z)); }
inline size_t cornerIndex(int x, int y, int z) {
    return size_t(x) + kCorners * (size_t(y) + kCorners * size_t(z));
}
// Offset of coefficient k of `channel` at `cell` in a light volume.
inline size_t lightOffset(int channel, size_t cell, int k) { return (size_t(channel) * kCells + cell) * 4 + k; }

using LightVolume = std::vector<float>;     // 3 · kCells · 4
using GeometryVolume = std::vector<float>;  // kCornerCount · 4
LightVolume emptyLightVolume();
GeometryVolume emptyGeometryVolume();

// Total flux of a light volume per channel, W: Σ over cells of ∫ I dω = 2√π·c_0.
glm::dvec3 totalFlux(const LightVolume& v);

// The light range of a volume, for the LPV debug views' own exposure: the 99th percentile over
// the cells holding light of a cell's mean radiance, c_0·Y_00 / h² (luminance, Rec. 709 weights),
// × indirect_intensity, in W/(m²·sr). A white surface lit by a hemisphere of that radiance has
// E/π equal to it. Device independent: it reads the injected light, which every device has.
// 0 for a volume without light.
double lightRange(const LightVolume& injected, double cellSize, double indirectIntensity);

// Adds a surface's blocking potential at corner texel `corner`: area / h² of a surface facing
// `normal` (Kaplanyan & Dachsbacher's B(ω) = A⟨n|ω⟩₊/h²), as 4/3 × its clamped-cosine L1
// projection: L1 reaches 3/4 of the lobe's peak, and a surface seen head-on should block by its
// projected area.
void addBlocker(GeometryVolume& g, size_t corner, const glm::vec3& normal, float areaOverCellArea);
// The share of light travelling along `dir` that the blockers of one SH set stop:
// clamp(B(−dir), 0, 1), surfaces facing against the light.
float blocking(const Sh4& geometry, const glm::vec3& dir);

// Adds an emitter's clamped-cosine lobe to a cell: intensity I(ω) = flux/π·max(0, n·ω), whose
// integral is `flux` (per channel).
void injectLobe(LightVolume& v, size_t cell, const glm::vec3& normal, const glm::vec3& flux);

struct PropagationStats {
    glm::dvec3 sent{0.0};     // flux the step moved between cells of the volume
    glm::dvec3 leaving{0.0};  // flux sent out through the volume's boundary
    glm::dvec3 blocked{0.0};  // flux the geometry stopped
};
// One propagation step: `dst` = what `src` passes to its six neighbours (not accumulated). Each
// source cell sends its intensity toward the five faces of each neighbour it sees (the far face,
// solid angle 0.4006696846 sr, and four side faces, 0.4234413544 sr each: together 4π over the six
// neighbours), each face's flux reprojected as a clamped-cosine lobe along the face normal at the
// neighbour's centre. Face fluxes an L1 lobe would make negative (behind a strong lobe) are clamped
// to zero and the rest scaled so each cell sends exactly its flux; then × `weight`, and × the
// geometry's transmission at the shared face (skipped with `occlude` false).
void propagationStep(const GeometryVolume& geometry, const LightVolume& src, LightVolume& dst,
                     float weight, bool occlude, PropagationStats* stats = nullptr);
// propagationStep's six neighbours (offset from source to destination, in this order) and each
// one's five faces (the far face first): the direction of the face's centre from the source's
// centre, its solid angle, and the unit lobe a face's flux becomes at the destination
// (clampedCosine(face normal, 1/π)). The renderer's propagation pass reads this table, so both
// step through the same values in the same order.
struct PropagationFace {
    glm::vec3 dir{0.0f};
    float solidAngle = 0.0f;
    Sh4 lobe{};
};
struct PropagationNeighbour {
    glm::ivec3 offset{0};
    int axis = 0;
    std::array<PropagationFace, 5> faces{};
};
const std::array<PropagationNeighbour, 6>& propagationNeighbours();
// The `weight` each step of Volumes::propagate passes to propagationStep for lpv.propagation_weight
// w: w^(1/32). The seed calls w a per-neighbour propagation strength (default 0.01) without a
// scale; as a per-step factor 0.01 would leave only the injected light. Read per neighbour step
// and compounded over a cascade's 32 cells, w is the share of the light left after it has crossed
// the whole cascade: 1 conserves energy, the default 0.01 keeps 0.866 per step (0.56 after the
// default 4 steps), 0 keeps the injected light only. Higher still spreads faster and leaks more.
float propagationStepWeight(double propagationWeight);

// ---- The whole LPV of a scene -------------------------------------------------------------------

struct Cascade {
    CascadeLayout layout;
    GeometryVolume geometry;
    LightVolume injected;     // sun and local lights
    LightVolume accumulated;  // injected + every propagation step; empty when the renderer propagates
    glm::dvec3 injectedFlux{0.0};
    size_t sunSurfels = 0;    // surfels the sun lights (at least partly visible)
};

// What happened to one local light.
struct LightInjection {
    size_t light = 0;
    int cascade = -1;         // where it went; -1 when nowhere
    bool injected = false;
    std::string reason;       // why not, in words: empty when injected
    size_t surfels = 0;       // surfels it lit
};

struct Inputs {
    // Tracer (its heightfield and skirt), sun and albedo. The sky is not read: the LPV carries the
    // sun's and the lights' first bounce.
    const BakeLighting* lighting = nullptr;
    const std::vector<LocalLight>* lights = nullptr;  // null: none
};

struct Sample {
    glm::vec3 irradiance{0.0f};  // W/m², × indirect_intensity
    glm::vec3 specular{0.0f};    // quality 2: radiance toward the eye along the mirror direction, × indirect_intensity
};

// Where the injected light is propagated: here (Cpu: `accumulated` filled, evaluate() works), or
// by the renderer's compute pass when it binds the volumes (Renderer: `accumulated` left empty;
// TerrainRenderer::setLpv). The CPU's propagation is the reference the renderer's is tested
// against.
enum class Propagation { Cpu, Renderer };

class Volumes {
public:
    // Places the cascades for the camera, builds their geometry, injects the sun and (with
    // local_lights) the lights, and (Propagation::Cpu) propagates.
    Volumes(const LpvSettings& settings, const Inputs& inputs, const glm::dvec3& camera,
            const glm::dvec3& viewDir, Propagation propagation = Propagation::Cpu);

    const LpvSettings& settings() const { return settings_; }
    const std::vector<Cascade>& cascades() const { return cascades_; }
    const std::vector<LightInjection>& lightInjections() const { return lights_; }
    // False when the renderer propagates: then only the geometry, the injection and
    // ambientOcclusion() are here, and evaluate() and radianceAt() throw std::logic_error.
    bool propagated() const { return propagated_; }

    // At position p with unit normal n; `toEye` (unit, toward the viewer) is read by quality 2.
    Sample evaluate(const glm::vec3& p, const glm::vec3& n, const glm::vec3& toEye, int quality) const;
    Sample evaluate(const glm::vec3& p, const glm::vec3& n, const glm::vec3& toEye) const {
        return evaluate(p, n, toEye, settings_.quality);
    }

    // The blended radiance SH at p (intensity / h², cascades blended by their fades), per channel;
    // weight = the cascades' total weight there (0 outside all).
    std::array<Sh4, 3> radianceAt(const glm::vec3& p, float* weight = nullptr) const;
    // The blended blocking SH at p.
    Sh4 geometryAt(const glm::vec3& p) const;
    // The cascades' total weight at p (0 outside all) and the cell of the one that weighs most
    // (ties: the finer).
    float weightAt(const glm::vec3& p, double* cellSize = nullptr) const;
    // The cascades' cells blended by their weights at p, 0 outside all: ambientOcclusion's step,
    // which unlike the dominant cell does not jump where one cascade takes over from another.
    double blendedCellSize(const glm::vec3& p) const;
    // The sky visibility the geometry volume gives a surface at p facing n (1 open): over
    // kAoDirections cosine-weighted directions ω, the light left after marching from half a cell
    // above p out of the volumes, a blended cell a step, each step keeping 1 − blocking by the
    // surfaces there that face p. Against the heightfield's traced visibility in
    // docs/lighting.md.
    float ambientOcclusion(const glm::vec3& p, const glm::vec3& n) const;
    // A cascade's fade weight at p: 1 inside, falling to 0 over fade_range cells at its faces.
    float fadeWeight(int cascade, const glm::vec3& p) const;

private:
    void buildGeometry(Cascade& c, const Heightfield& hf, bool skirt) const;
    void injectSun(Cascade& c, int cascade) const;
    void injectLights();
    void propagate(Cascade& c) const;
    glm::vec3 irradianceAt(const glm::vec3& q, const glm::vec3& n, int quality) const;

    LpvSettings settings_;
    Inputs inputs_;
    bool propagated_ = true;
    std::vector<Cascade> cascades_;
    std::vector<LightInjection> lights_;
};

// ---- Measurement against the reference bake -----------------------------------------------------

// LPV irradiance against the bake's one-bounce irradiance at ground points: at each (x, z), the
// terrain point and its normal; `lpv` what Volumes::evaluate gives there (quality as set),
// `reference` the irradiance the terrain's sunlit surfaces reflect to it after one bounce, from
// the bake's irradiance cache with the sky black (IrradianceCache::indirectAt).
struct GroundComparison {
    std::vector<glm::vec3> positions, normals;
    std::vector<glm::vec3> lpv, reference;
    double meanLpv = 0, meanReference = 0;  // luminance
    double relativeRms = 0;                 // RMS of the luminance difference / RMS of the reference
};
// `points`: (x, z) ground positions; `cacheResolution`/`cacheRays` size the reference's cache.
GroundComparison compareWithOneBounce(const Volumes& volumes, const BakeLighting& lighting,
                                      const std::vector<glm::vec2>& points, int cacheResolution,
                                      int cacheRays);

}  // namespace terralux::lpv
