#pragma once
// Water: Gerstner waves and their dispersion, the steepness rule, the level "auto" stands for,
// and the distance to shore (docs/lighting.md, "Water"). The waves' terms are written once, in
// shaders/water_math.glsl: evaluated here in double and by the viewport's shaders in float;
// tests/render/test_shader_math.cpp holds the two together.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "ShaderMath.h"
#include "scene/SceneDescription.h"
#include "terrain/Heightfield.h"

namespace terralux::water {

inline constexpr double kGravity = TLX_GRAVITY;  // m/s², water_math.glsl's
inline constexpr double kWaterIor = 1.33;
inline constexpr double kWaterF0 = 0.02;  // Schlick's F0 for ((1.33 − 1) / (1.33 + 1))²

// One wave as the evaluator uses it: unit travel direction in (x, z), wave number k = 2π/λ,
// amplitude A, angular frequency in deep water ω = √(g·k), phase φ.
struct WaveTerms {
    glm::dvec2 direction{1.0, 0.0};
    double k = 1.0, amplitude = 0.0, omegaDeep = 0.0, phase = 0.0;
};
WaveTerms waveTerms(const GerstnerWave& wave);
// ω at water depth h (metres; unset = deep): √(g·k·tanh(k·h)), or √(g·k) without a depth.
double angularFrequency(double k, std::optional<double> depth);
// Σ k_i·A_i: at most 1, or the crests loop.
double summedSteepness(const std::vector<GerstnerWave>& waves);
// Empty when the set is valid; else the rule it breaks, in words with the values.
std::string checkWaves(const std::vector<GerstnerWave>& waves);

// The surface at rest position (x, z) and time t: displacement from (x, level, z), and the
// unit normal. `depth` feeds the dispersion when depth-aware (unset: deep water); `fade` in [0, 1]
// scales every amplitude (the shore fade).
struct SurfacePoint {
    glm::dvec3 displacement{0.0};
    glm::dvec3 normal{0.0, 1.0, 0.0};
};
SurfacePoint gerstner(const std::vector<WaveTerms>& waves, glm::dvec2 xz, double t,
                      std::optional<double> depth = std::nullopt, double fade = 1.0);

// Amplitude scale by distance to shore: smoothstep(0, fadeDistance, distance) (1 when the fade
// distance is 0).
double shoreFade(double distance, double fadeDistance);

// What water.level "auto" finds (docs/lighting.md, "Water"): the water surface the DEM shows, or
// none. DEMs store a sea or a lake as one height over the water body, so a surface is a connected
// area of cells within kFlatTolerance of one height that is a local minimum (no neighbour lower),
// at least kMinWaterCells cells and a ten-thousandth of the DEM, and whose level floods little dry
// land below it (at most a tenth of its own area). Of those, the largest.
inline constexpr float kFlatTolerance = 0.01f;  // metres
inline constexpr size_t kMinWaterCells = 64;
struct AutoLevel {
    std::optional<double> level;  // engine space; unset when the DEM shows no water
    size_t cells = 0;             // of the surface found
    double share = 0.0;           // cells / the DEM's cells
    std::string summary;          // one line: what was found, or that nothing was
};
AutoLevel autoLevel(const Heightfield& hf);
// The water level in engine space: settings.level, or what autoLevel finds (unset: no water).
std::optional<double> waterLevel(const WaterSettings& settings, const Heightfield& hf);

// The shore fade in metres: settings.shore_fade_distance, or two of the DEM's cells (the larger
// spacing) when unset. The shore distance is known at the vertices only, so a fade shorter than
// a cell jumps from nothing to full between two of them; two cells make a ramp on any DEM (a fixed
// 50 m was under one cell of an 81 m tile).
double shoreFadeDistance(const WaterSettings& settings, const Heightfield& hf);

// Euclidean distance in metres from every DEM vertex to the nearest land vertex (height >=
// level), 0 on land; vertices with no land anywhere get +infinity. Row-major like the heights.
// Exact squared distance transform of Felzenszwalb & Huttenlocher (2012), separable in x then z,
// with the DEM's cell sizes.
std::vector<float> shoreDistance(const Heightfield& hf, double level);

// The presets the Water dock offers: "calm lake", "choppy lake", "open sea".
std::vector<std::string> wavePresetNames();
std::vector<GerstnerWave> wavePreset(const std::string& name);  // empty for an unknown name

}  // namespace terralux::water
