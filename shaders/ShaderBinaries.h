#pragma once
// SPIR-V compiled from the GLSL in this folder at build time and embedded in the binary.

#include <cstdint>
#include <span>

namespace terralux::shaders {
std::span<const uint32_t> terrainVert();            // without probe light
std::span<const uint32_t> terrainProbeLightVert();  // with the probe pass's per-vertex light
std::span<const uint32_t> terrainFrag();        // the sun unshadowed
std::span<const uint32_t> terrainShadowFrag();  // with the shadow cascades bound
// The same two with the reflection probes bound in the lights set.
std::span<const uint32_t> terrainReflectionFrag();
std::span<const uint32_t> terrainShadowReflectionFrag();
// The four again with the LPV and local-lights set bound (TLX_LPV).
std::span<const uint32_t> terrainLpvFrag();
std::span<const uint32_t> terrainShadowLpvFrag();
std::span<const uint32_t> terrainReflectionLpvFrag();
std::span<const uint32_t> terrainShadowReflectionLpvFrag();
std::span<const uint32_t> fullscreenVert();
std::span<const uint32_t> skyBackgroundFrag();
std::span<const uint32_t> antialiasFrag();  // the picture views' fxaa or 2x2 average (camera.antialiasing)
std::span<const uint32_t> shadowDepthVert();
std::span<const uint32_t> probeVerticesComp();
std::span<const uint32_t> lpvSampleComp();  // Volumes::evaluate at given points (TerrainRenderer::sampleLpv)
std::span<const uint32_t> lpvPropagateComp();  // propagation steps of the bound LPV (TerrainRenderer::setLpv)
std::span<const uint32_t> markersVert();
std::span<const uint32_t> markersFrag();
std::span<const uint32_t> leavesVert();
std::span<const uint32_t> gizmosVert();       // volume bounds and handles: one line per instance
std::span<const uint32_t> waterVert();
std::span<const uint32_t> waterFrag();        // the sun unshadowed
std::span<const uint32_t> waterShadowFrag();  // with the shadow cascades bound
std::span<const uint32_t> waterReflectionFrag();        // the reflection probes bound
std::span<const uint32_t> waterShadowReflectionFrag();  // both
}  // namespace terralux::shaders
