#pragma once
// glTF 2.0 scene export (docs/formats.md): the terrain mesh, its material, the baked SH probe volumes
// and the geo/bake metadata, written as
//
//   <outDir>/scene.gltf
//   <outDir>/scene.bin                    only when the terrain has triangles; also holds the
//                                         terrain's albedo texture (a PNG) when it has one
//   <outDir>/sh_coeffs/<volume>.shprobe   one file per probe volume
//   <outDir>/scenarios/<volume>.<scenario>.shprobe
//                                         each lighting scenario's grids, the layout of sh_coeffs/
//   <outDir>/reflection/...               the reflection probes' files, when the caller gives them
//
// Engine space is glTF space (Y up, right-handed: X east, Y up, Z south), so nothing is converted.
// The mesh uses the bake's triangulation (Heightfield.h) wound counter-clockwise seen from +Y, so
// glTF front faces point up. The root-level extensions are listed in `extensionsUsed` and never
// in `extensionsRequired`:
//   VULKAN_SCHNEE_engine_properties  {"shProbeGrids": [...]} one entry per .shprobe file, sorted by
//                                    file name; every number equals that file's header exactly
//   TERRALUX_geo                     CRS, origin, vertical scale, cell size, grid size, mesh stride
//   TERRALUX_bake                    the caller's JSON object, verbatim
//   TERRALUX_lighting                the caller's JSON object, verbatim, when it gives one; with
//                                    lighting scenarios, plus "scenarios": the default's files and
//                                    each scenario's, with its name and its lighting object
// With water, a second node and mesh named `water`: a rectangle over the footprint at the water
// level, whose material uses KHR_materials_transmission and KHR_materials_ior (both used, never
// required). Local lights are KHR_lights_punctual lights (used, never required), one node each
// ("light <i>") at the light's position, turned so its −Z points along a spot's direction.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include "AtomicFile.h"
#include "ShProbeFile.h"
#include "scene/SceneDescription.h"
#include "terrain/Heightfield.h"
#include "terrain/SurfaceAlbedo.h"

namespace terralux {

struct GltfProbeVolume {
    std::string name;  // file stem: 1 to 64 of [A-Za-z0-9_-], unique within a scene
    ShProbeGrid grid;
    // When set, written as sh_coeffs/<name>.probes.json in the same commit (ProbeDiagnosticsFile.h).
    std::string diagnostics;
};

// A lighting scenario of the scene (docs/formats.md, "Lighting scenarios"): the same volumes as
// GltfSceneInput::volumes (names, dimensions, origin and spacing), lit otherwise.
struct GltfScenario {
    std::string name;  // 1 to 64 of [A-Za-z0-9_-], unique, not "default"
    std::vector<GltfProbeVolume> volumes;
    // Merged into its entry of TERRALUX_lighting.scenarios (the sun and sky it was lit with).
    nlohmann::json lighting = nlohmann::json::object();
};

// The water plane of the scene (docs/formats.md, "glTF scene"): the footprint's rectangle at the
// level, with a transmissive material of index of refraction 1.33.
struct GltfWater {
    float level = 0.0f;              // engine y, finite
    glm::vec3 color{0.0f};           // base colour factor (water.color), each channel in [0, 1]
    float roughness = 0.05f;         // roughnessFactor (water.roughness), in [0, 1]
};

struct GltfSceneInput {
    const Heightfield* heightfield = nullptr;
    // A tile's traced terrain (a larger window of the same grid as `heightfield`,
    // Heightfield::window), or null: the mesh's vertex normals are taken there, so a tile's border
    // vertices get the normals its neighbour's get, and `albedoTexture` is over it.
    const Heightfield* surroundings = nullptr;
    glm::vec3 albedo{0.3f};  // base colour factor, each channel in [0, 1]
    // When set and not empty: the terrain's base colour texture instead (docs/formats.md), an
    // sRGB-encoded 8-bit PNG embedded in scene.bin, with TEXCOORD_0 on its texel centres and a
    // white base colour factor. Must be over `heightfield`.
    const SurfaceAlbedo* albedoTexture = nullptr;
    float roughness = 1.0f;  // the material's roughnessFactor (terrain.roughness), in [0, 1]
    double verticalScale = 1.0;  // recorded in TERRALUX_geo; the heights are exported as they are
    std::vector<GltfProbeVolume> volumes;
    // Written as scenarios/<volume>.<scenario>.shprobe and listed in TERRALUX_lighting.scenarios
    // (which then needs `lighting`); `defaultLighting` is the default scenario's entry's object.
    std::vector<GltfScenario> scenarios;
    nlohmann::json defaultLighting = nlohmann::json::object();
    nlohmann::json bake = nlohmann::json::object();  // TERRALUX_bake, must be an object
    // TERRALUX_lighting: an object (the bake writes the project's lighting, app/SceneLighting.h),
    // or null for no such extension.
    nlohmann::json lighting = nullptr;
    // Unset: no water node (a one-sample-wide heightfield, with no footprint, has none either).
    std::optional<GltfWater> water;
    // KHR_lights_punctual, in this order. Intensity in candela = LocalLight::intensity; cone
    // angles in radians.
    std::vector<LocalLight> lights;
    std::string generatorVersion;                    // asset.generator = "Terralux <version>"
    // Vertex budget: a larger heightfield is exported with every k-th row and column (the smallest
    // k that fits, the last row and column always included); k is TERRALUX_geo.meshStride. The
    // default is no budget: the exported mesh is the surface the bake traced, sample for sample.
    size_t meshMaxVertices = std::numeric_limits<size_t>::max();
    // false: only the sh_coeffs files (export.gltf off), staged and committed the same way.
    bool scene = true;
    // Files of reflection/ (the reflection probes' .rprobe and simvx records), committed with the
    // rest: name within reflection/ and contents.
    std::vector<std::pair<std::string, std::vector<uint8_t>>> reflectionFiles;
    // More top-level files written with the rest (the bake report): name and contents.
    std::vector<std::pair<std::string, std::string>> extraFiles;
    // Top-level names the export owns even when it does not write them this time (lpv.ini): an
    // earlier export's file of that name is removed in the same commit.
    std::vector<std::string> ownedFiles;
};

struct GltfExportResult {
    std::vector<std::filesystem::path> files;  // every file written, in outDir
    uint64_t bytes = 0;                         // their total size
};

// Writes the whole layout into `outDir` (created if missing). Every file is first written into a
// staging directory inside outDir (".staging-<unique>"); only when all were written is each renamed
// into place (the .shprobe files, then scene.bin, then scene.gltf). If any step fails, the files
// already replaced are restored, the staging directory is removed, and the files in outDir stay
// byte-identical to what they were before the call.
// The export owns every file in outDir/sh_coeffs/, outDir/scenarios/ and outDir/reflection/, scene.gltf, scene.bin
// and the extra files, and replaces them as a whole: an owned file this export does not write (the .shprobe of a renamed
// volume, scene.gltf when the scene is off) is removed in the same commit, and put back if the
// commit fails. Nothing else in outDir is touched.
// A heightfield with a single row or column has no triangles: the scene then has no mesh, no buffer
// and no scene.bin, only the extensions (TERRALUX_geo.meshStride is 1).
// Throws FileWriteError for filesystem failures, ShProbeError for a grid that cannot be encoded and
// std::runtime_error for other invalid input, each with a one-line message naming the file.
GltfExportResult exportGltfScene(const std::filesystem::path& outDir, const GltfSceneInput& input);

// The terrain mesh the scene would carry for `hf` (every k-th row and column within
// meshMaxVertices): its stride, or std::runtime_error naming `gltfPath` when a glTF cannot hold
// it (32-bit indices, a buffer of at most 4 GiB). The bake asks before it traces anything, so a
// terrain too large is refused at once rather than after the probes.
size_t checkTerrainMesh(const Heightfield& hf, size_t meshMaxVertices, const std::filesystem::path& gltfPath);
// Top-level files of `outDir` (name, contents), written as exportGltfScene writes its own: staged,
// then committed together, or not at all (earlier files put back). Throws FileWriteError.
void writeFilesTogether(const std::filesystem::path& outDir,
                        const std::vector<std::pair<std::string, std::string>>& files);

// The files exportGltfScene writes for `input`, relative to outDir, in the order it commits them.
std::vector<std::string> exportedFileNames(const GltfSceneInput& input);

// Reads scene.gltf back with tinygltf and returns the default scene's
// VULKAN_SCHNEE_engine_properties.shProbeGrids array as written (for tests and tools). Throws
// std::runtime_error naming the file if it does not load or its scene has no such array.
nlohmann::json readShProbeGridEntries(const std::filesystem::path& gltfFile);

}  // namespace terralux
