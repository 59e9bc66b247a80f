#pragma once
// What a bake knows about its probes beyond their coefficients: where each probe sits, which were
// moved up out of the terrain, which were rejected, the octree leaves, and an interpolation-error
// map over the ground. The probe-validity and interpolation-error debug views (docs/lighting.md) and the leaf overlay draw it. `.shprobe` carries none of this, so the bake writes it beside
// each file (io/ProbeDiagnosticsFile.h).

#include <cstdint>
#include <optional>
#include <span>
#include <unordered_map>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "bake/AdaptivePlacement.h"
#include "bake/ProbePlacement.h"
#include "bake/SphericalHarmonics.h"
#include "terrain/Heightfield.h"

namespace terralux {

// docs/lighting.md interpolation error at the points of a regular grid over the ground: point (i, j)
// lies at (x0 + i·step, z0 + j·step), `height` above the terrain surface. The error is the
// relative irradiance error of the interpolated probes against a probe baked at the point.
struct ErrorMap {
    uint32_t nx = 0, nz = 0;
    float x0 = 0.0f, z0 = 0.0f, step = 1.0f;
    float height = 0.0f;
    std::vector<float> error;  // nx·nz, i fastest; NaN where no probe covers the point

    bool empty() const { return error.empty(); }
};

// Mean, 95th percentile and max over the covered points.
struct ErrorMapStats : Spread {
    size_t points = 0;     // covered by probes
    size_t uncovered = 0;  // above the terrain inside the grid footprint with no probe around
};
ErrorMapStats errorMapStats(const ErrorMap& map);

struct ProbeDiagnostics {
    // Per probe of the .shprobe file, in its record order (valid probes in placement order).
    std::vector<glm::vec3> positions;
    std::vector<uint8_t> moved;         // 1: moved up out of the terrain (adaptive minimum leaves)
    // Per probe, the bake's relative standard error of its irradiance (docs/lighting.md,
    // "Standard error"); empty when not known (a sidecar written before it was kept).
    std::vector<float> standardError;
    // Probes placed inside the terrain and left out of the file.
    std::vector<glm::vec3> rejected;
    // Adaptive volumes: every octree leaf, min corner xyz and edge (metres).
    std::vector<glm::vec4> leaves;
    ErrorMap errorMap;

};

// Positions, moves, rejections and leaves of a layout (no error map), and the valid probes'
// standard errors when `standardError` holds one per placed probe (ProbeBake::standardError).
ProbeDiagnostics describeProbes(const ProbeLayout& layout, std::span<const float> standardError = {});

// How far above the ground a volume's error map measures: a terrain grid's or surface volume's own
// probe height (so the map shows the horizontal interpolation alone), otherwise 2 % of a cell, the
// clearance of a moved probe.
float errorMapHeight(const ProbeVolumeSettings& volume, const ProbeLayout& layout);

// The points of the map (error all NaN): `resolution` points along the longer side of the
// footprint shared by the grid box and the terrain, square spacing. 0 gives an empty map.
ErrorMap errorMapGrid(const ProbeLayout& layout, const Heightfield& hf, int resolution, float height);

// The error map of a baked layout: every point of errorMapGrid with probes around it is baked with
// `baker` (point k keyed from `seed` and k) and compared with interpolateProbes over `sh`
// (aligned with layout.positions). The baker's exceptions (BakeCancelled) pass through.
// `truths`, when given, keeps every point's truth by its index in the map: a later map over the
// same points (another layout of the same footprint, the same seed) reads them instead of baking
// them again, and bakes only the points it adds (keyed alike, so they are the same probes).
ErrorMap measureErrorMap(const ProbeLayout& layout, const std::vector<sh::ShRgb>& sh,
                         const Heightfield& hf, const ProbeBaker& baker, int resolution,
                         float height, uint64_t seed,
                         std::unordered_map<size_t, sh::ShRgb>* truths = nullptr);

}  // namespace terralux
