#pragma once
// Terrain-local reflection probes (docs/lighting.md, "Reflection probes"): where they go, what
// each one sees of the lit terrain and the sky, and the two encodings that store it, with the
// lookups the renderer and the error measurement share.
//
// Cube faces follow the Vulkan / OpenGL cube-map convention (Vulkan spec, "Cube Map Face
// Selection"), so an engine uploads the texels as they are: face order +X, −X, +Y, −Y, +Z, −Z in
// the engine frame (X east, Y up, Z south); on face f a texel (s, t) in [0, 1]² (t = 0 the top
// row) looks along, with u = 2s − 1 and v = 2t − 1:
//   +X (1, −v, −u)   −X (−1, −v, u)   +Y (u, 1, v)   −Y (u, −1, −v)   +Z (u, −v, 1)   −Z (−u, −v, −1).

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "bake/DiffuseBake.h"
#include "bake/ProbePlacement.h"
#include "scene/SceneDescription.h"
#include "terrain/Heightfield.h"

namespace terralux {

// The most probes the simvx box records hold (seed 002's MAX_PROBES).
inline constexpr int kSimvxMaxProbes = 8;

// Where a reflection grid's probes go (seed 000's placement rules, a terrain probe volume's).
struct ReflectionLayout {
    std::array<int, 2> dims{1, 1};      // (nx, nz); scene order is row-major, x fastest
    glm::vec2 origin{0.0f};             // (x, z) of probe 0
    glm::vec2 spacing{0.0f};            // between neighbours, 0 on a one-probe axis
    // The (x, z) extent of each probe's cell: the spacing, or the footprint's on a one-probe axis.
    glm::vec2 cellSize{0.0f};
    std::vector<glm::vec3> positions;   // capture points, engine space: the traced surface + offset
    std::vector<float> lowestBelow;     // per probe, the lowest traced surface under its cell
    float blendDistance = 0.0f;         // fallback_blend_distance, resolved

    size_t count() const { return positions.size(); }
    // The probe's box (docs/formats.md, "Reflection-probe box records"): half the cell in x and z;
    // in y half the span from the lowest surface under the cell to the probe height plus the
    // cell size (the larger of its x and z extents). The box is centred on the capture point.
    glm::vec3 halfExtent(size_t i) const;
};

// Throws PlacementError naming the reflection_probes setting, the value and the rule.
ReflectionLayout placeReflectionProbes(const ReflectionProbeSettings& settings, const Heightfield& hf);

// Texels a side of cube mip `level` for a mip-0 side of `size`.
inline int cubeMipSize(int size, int level) { return std::max(1, size >> level); }
// The smallest mip's side: a GGX lobe at roughness 1 is as wide as the cosine lobe, which 4×4
// texels a face still follow (a 1×1 face would turn it into six flat colours).
inline constexpr int kSmallestCubeMip = 4;
// Mip levels of a cube of side `size` (a power of two, at least 8): down to 4×4, log2(size) − 1.
int cubeMipCount(int size);
// The GGX roughness mip `level` of `count` is prefiltered for: level / (count − 1), 0 for one level.
float cubeMipRoughness(int level, int count);
// The unit direction through (s, t) in [0, 1]² of cube face `face` (convention above).
glm::vec3 cubeDirection(int face, float s, float t);
// The face a direction falls on and its (s, t) there.
int cubeFace(const glm::vec3& dir, float& s, float& t);
// Exact solid angle of texel (x, y) on a face `size` texels a side.
float cubeTexelSolidAngle(int size, int x, int y);

// One baked probe. Both encodings keep the six face colours (the inspector shows them); the
// cubemap encoding adds its texels: per mip level, per face, rows top to bottom, x fastest.
struct ReflectionProbe {
    uint32_t id = 0;                    // its grid index: a re-bake keeps it
    glm::vec3 position{0.0f};
    glm::vec3 halfExtent{0.0f};
    std::array<glm::vec3, 6> faces{};   // mean radiance over each face, +X, −X, +Y, −Y, +Z, −Z
    std::vector<glm::vec3> texels;      // cubemap only
};

struct ReflectionProbeSet {
    ReflectionEncoding encoding = ReflectionEncoding::Cubemap;
    int faceSize = 0;                   // cubemap: mip 0's side; faces: 0
    int mipCount = 1;                   // cubemap: cubeMipCount(faceSize); faces: 1
    std::array<int, 2> dims{1, 1};
    glm::vec2 origin{0.0f}, spacing{0.0f}, cellSize{0.0f};
    float strength = 1.0f;
    float blendDistance = 0.0f;
    std::vector<ReflectionProbe> probes;  // scene order

    // Texels of one probe's whole chain, and the offset of (level, face) within it.
    size_t texelsPerProbe() const;
    size_t texelOffset(int level, int face) const;
    // The probe's prefiltered radiance toward `dir` for GGX `roughness`, as the renderer reads
    // it: faces, the ambient-cube blend Σ d_i² · face(sign d_i, i) at any roughness; cubemap,
    // bilinear (seamless across face edges, as cube-map hardware filters) at the two mips around
    // roughness × (mipCount − 1), blended.
    glm::vec3 evaluate(size_t probe, const glm::vec3& dir, float roughness) const;
};

// The radiance cube one probe sees before prefiltering: 6 faces of size², same layout as mip 0.
struct RadianceCube {
    int size = 0;
    std::vector<glm::vec3> texels;
    glm::vec3& at(int face, int x, int y) { return texels[(size_t(face) * size + y) * size + x]; }
    const glm::vec3& at(int face, int x, int y) const { return texels[(size_t(face) * size + y) * size + x]; }
};

// The light a reflection ray brings back: probeRayRadiance's model (lit terrain, water, sky), and
// `ground` where a ray heading down escapes (past the footprint with the skirt off).
struct ReflectionLighting {
    const BakeLighting* lighting = nullptr;
    const IrradianceCache* cache = nullptr;  // required: terrain hits read their light from it
    int bounces = 1;                          // >= 1
    glm::vec3 ground{0.0f};                   // radiance of the ground beyond the terrain
};
// The radiance of ground with albedo `color` under the open sky and the unshadowed sun.
glm::vec3 groundRadiance(const BakeLighting& lighting, const glm::vec3& color);

// Traces the radiance cube around `position`: `raysPerTexel` rays jittered over each texel
// (weighted by the texel's solid-angle density), seeded by `seed` only.
RadianceCube traceRadianceCube(const ReflectionLighting& light, const glm::vec3& position, int size,
                               int raysPerTexel, uint64_t seed, uint64_t* rays = nullptr);
// Solid-angle-weighted mean of each face.
std::array<glm::vec3, 6> faceMeans(const RadianceCube& cube);
// The split-sum prefiltered mip chain (Karis, "Real Shading in Unreal Engine 4", SIGGRAPH 2013,
// with N = V = R): mip m holds ∫ L(l) D(h) (n·l) dl / ∫ D(h) (n·l) dl at roughness
// cubeMipRoughness(m), integrated over the unfiltered cube reduced to mip m's resolution (mip 0
// is the cube).
std::vector<glm::vec3> prefilterCube(const RadianceCube& cube);
// The same integral, brute force over every texel of `cube`, for one direction.
glm::vec3 prefilteredRadiance(const RadianceCube& cube, const glm::vec3& dir, float roughness);

// Bakes every probe of `layout` at settings.resolution and settings.rayCount into a cubemap set
// (the face colours included); toEncoding then keeps what settings.encoding stores.
// Deterministic: each probe's rays depend on its id and `seed` only, whatever the threads.
ReflectionProbeSet bakeReflectionProbes(const ReflectionLighting& light,
                                        const ReflectionProbeSettings& settings,
                                        const ReflectionLayout& layout, uint64_t seed,
                                        const BakeControl& control, uint64_t* rays = nullptr,
                                        std::vector<RadianceCube>* cubes = nullptr);
// Drops the cube texels of a set whose encoding is faces.
void toEncoding(ReflectionProbeSet& set, ReflectionEncoding encoding);

// How far each encoding is from the truth (docs/lighting.md, "Reflection probes"): per probe, the
// relative RMS of the luminance of prefiltered radiance over 256 fixed directions, the set's faces
// and its mip chain against brute-force prefiltering of a reference cube traced at four times the
// resolution a side with the same rays per texel (16× the rays); mean, p95 and max over probes.
// `set` must be a cubemap set baked from `layout` with `light`.
// The roughnesses the encodings' error is reported at: from the terrain's floor to 1.
inline const std::vector<float> kReflectionErrorRoughness{0.25f, 0.5f, 0.75f, 1.0f};
struct ReflectionError {
    float roughness = 0.0f;
    Spread faces, cubemap;
};
struct ReflectionErrorReport {
    std::vector<ReflectionError> byRoughness;
    int referenceResolution = 0;
    uint64_t rays = 0;
};
ReflectionErrorReport measureReflectionError(const ReflectionLighting& light,
                                             const ReflectionProbeSettings& settings,
                                             const ReflectionProbeSet& set,
                                             const std::vector<float>& roughnesses, uint64_t seed,
                                             const BakeControl& control);
// The per-probe term: relative RMS of evaluate(probe, d, roughness) with `encoding` against
// prefilteredRadiance(reference, d, roughness) over the 256 directions.
float reflectionProbeError(const ReflectionProbeSet& set, size_t probe, ReflectionEncoding encoding,
                           const RadianceCube& reference, float roughness);
// The same against the luminance of that reference over the 256 directions (referenceLuminance),
// for a truth measured once and read by many sets.
float reflectionProbeError(const ReflectionProbeSet& set, size_t probe, ReflectionEncoding encoding,
                           const std::vector<double>& reference, float roughness);
std::vector<double> referenceLuminance(const RadianceCube& reference, float roughness);

}  // namespace terralux
