#include "render/features/Packing.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>
#include <glm/trigonometric.hpp>

#include "water/Water.h"

namespace terralux::features {

blocks::CameraBlock packCamera(const RenderSettings& s, float extent, const DebugView& view) {
    const float aspect = float(s.width) / float(s.height);
    blocks::CameraBlock camera;
    camera.viewProj = s.camera.viewProjection(aspect, extent);
    camera.invViewProj = glm::inverse(camera.viewProj);
    camera.position = s.camera.position();
    camera.farPlane = s.camera.planes(extent).farPlane;
    camera.viewportSize = glm::vec2(float(s.width), float(s.height));
    camera.invViewportSize = 1.0f / camera.viewportSize;
    camera.debugView = s.debugView;
    camera.linearOutput = s.linearOutput ? 1 : 0;
    // What the per-vertex attribute holds: 2 the traced sun visibility, 1 the probe diagnostics,
    // 0 probe light.
    camera.vertexAttribute = view.needs.sunVisibility ? 2 : view.needs.probeDiagnostics ? 1 : 0;
    return camera;
}

blocks::CameraBlock packMirroredCamera(const RenderSettings& s, const blocks::CameraBlock& camera, float extent,
                                       float level, float width, float height) {
    const float aspect = float(s.width) / float(s.height);
    blocks::CameraBlock mirrored = camera;
    mirrored.viewProj = s.camera.reflectedViewProjection(aspect, extent, level);
    mirrored.invViewProj = glm::inverse(mirrored.viewProj);
    mirrored.position = s.camera.reflectedPosition(level);
    mirrored.viewportSize = glm::vec2(width, height);
    mirrored.invViewportSize = 1.0f / mirrored.viewportSize;
    mirrored.debugView = kViewBeauty;
    mirrored.linearOutput = 1;
    return mirrored;
}

blocks::SurfaceBlock packSurface(const RenderSettings& s, const SurfaceInputs& in) {
    blocks::SurfaceBlock surface;
    surface.albedo = s.albedo;
    surface.albedoFromMap = in.albedoMap ? 1.0f : 0.0f;
    surface.roughness = float(s.terrain.roughness);
    surface.exposure = s.exposure;
    surface.specularAA = s.terrain.specularAA ? 1.0f : 0.0f;
    surface.roughnessFloor = float(kRoughnessFloor);
    surface.footprintMin = in.footprintMin;
    surface.invFootprintSpan = glm::vec2(in.footprintSpan.x > 0.0f ? 1.0f / in.footprintSpan.x : 0.0f,
                                         in.footprintSpan.y > 0.0f ? 1.0f / in.footprintSpan.y : 0.0f);
    surface.normalAoMapSize = in.normalAoMapSize;
    surface.albedoMapSize = in.albedoMapSize;
    surface.aoOnSky = s.ao.enabled && in.ao ? 1.0f : 0.0f;
    surface.aoOnProbes = s.ao.enabled ? float(s.ao.strength) : 0.0f;
    surface.probeAoLevel = in.probeAoLevel;
    const DetailSettings& d = s.detail;
    surface.detailStrength = d.enabled ? float(d.normalStrength) : 0.0f;
    surface.detailScale = d.enabled ? float(d.scale) : 1.0f;
    surface.detailFade = d.enabled ? float(d.fadeDistance) : 0.0f;
    surface.albedoVariation = d.enabled ? float(d.albedoVariation) : 0.0f;
    return surface;
}

blocks::SunSkyBlock packSunSky(const RenderSettings& s) {
    blocks::SunSkyBlock sunSky;
    sunSky.sunDirection = s.sun.direction;
    sunSky.sunAngularRadius = s.sun.angularRadius;
    sunSky.sunIlluminance = s.sun.illuminance;
    for (int k = 0; k < 9; ++k) sunSky.skySh[k] = glm::vec4(s.skySh.c[size_t(k)], 0.0f);
    return sunSky;
}

blocks::AtmosphereBlock packAtmosphere(const FogSettings& fog) {
    blocks::AtmosphereBlock atmosphere;
    atmosphere.fogDensity = float(fog.density);
    atmosphere.fogFalloff = float(fog.scaleHeight > 0.0 ? 1.0 / fog.scaleHeight : 0.0);
    atmosphere.fogBase = float(fog.baseHeight.value_or(0.0));
    atmosphere.fogAnisotropy = float(fog.anisotropy);
    atmosphere.fogColor = fog.color.value_or(glm::vec3(0.0f));
    atmosphere.sunInscatter = float(fog.inscatter);
    return atmosphere;
}

blocks::ShadowBlock packShadows(const RenderSettings& s, const std::vector<Cascade>& cascades,
                                const CascadeRange& range, int resolution) {
    blocks::ShadowBlock block;
    for (size_t i = 0; i < cascades.size(); ++i) {
        block.lightViewProj[i] = cascades[i].lightViewProj;
        block.ends[int(i)] = float(cascades[i].farDistance);
        block.texel[int(i)] = cascades[i].texelSize;
        block.depthRange[int(i)] = cascades[i].depthRange;
    }
    block.forward = glm::normalize(s.camera.target - s.camera.position());
    block.nearDepth = float(range.nearDistance);
    block.depthBias = float(s.shadows.depthBias);
    block.normalBias = float(s.shadows.normalBias);
    block.tanSunRadius = std::tan(s.sun.angularRadius);
    block.mapResolution = float(resolution);
    block.cascadeCount = int(cascades.size());
    block.filterMode = int(s.shadows.filter);
    return block;
}

blocks::WaterBlock packWater(const RenderSettings& s, const WaterInputs& in) {
    const WaterSettings& ws = s.water;
    blocks::WaterBlock block;
    block.level = in.level;
    block.time = float(s.time);
    block.shoreFade = in.shoreFadeDistance;
    block.depthAware = ws.depthAware ? 1.0f : 0.0f;
    block.scatter = ws.color;
    block.roughness = float(ws.roughness);
    block.absorption = ws.absorption;
    block.planarReflection = ws.reflection == WaterReflection::Planar ? 1.0f : 0.0f;
    const size_t waves = std::min<size_t>(ws.waves.size(), WaterSettings::kMaxWaves);
    block.fieldSize = in.fieldSize;
    block.distortion = float(ws.distortion);
    block.waveCount = float(waves);
    block.meshSpacing = in.meshSpacing;
    for (size_t i = 0; i < waves; ++i) {
        const water::WaveTerms wave = water::waveTerms(ws.waves[i]);
        blocks::WaveRecord& r = block.waves[i];
        r.direction = glm::vec2(wave.direction);
        r.k = float(wave.k);
        r.amplitude = float(wave.amplitude);
        r.omegaDeep = float(wave.omegaDeep);
        r.phase = float(wave.phase);
    }
    return block;
}

std::vector<blocks::LocalLightRecord> packLocalLights(const std::vector<LocalLight>& lights, bool used) {
    std::vector<blocks::LocalLightRecord> records(std::max<size_t>(used ? lights.size() : 0, 1));
    for (size_t i = 0; used && i < lights.size(); ++i) {
        const LocalLight& l = lights[i];
        blocks::LocalLightRecord& r = records[i];
        const bool spot = l.type == LocalLightType::Spot;
        r.position = l.position;
        r.range = float(l.range);
        r.emitted = l.color * float(l.intensity);
        r.spot = spot ? 1.0f : 0.0f;
        const float len = glm::length(l.direction);
        r.direction = len > 0.0f ? l.direction / len : glm::vec3(0.0f, -1.0f, 0.0f);
        const float cosOuter = std::cos(glm::radians(float(l.outerConeDeg)));
        const float cosInner = std::cos(glm::radians(float(l.innerConeDeg)));
        r.cosOuter = cosOuter;
        r.invConeWidth = 1.0f / std::max(0.001f, cosInner - cosOuter);
    }
    return records;
}

blocks::OverlayBlock packOverlay(const RenderSettings& s, float smallestLeaf, float smallestLeafPixels) {
    blocks::OverlayBlock overlay;
    overlay.smallestLeaf = smallestLeaf;
    overlay.smallestLeafPixels = smallestLeafPixels;
    overlay.drawValid = s.showProbePositions ? 1 : 0;
    overlay.drawMovedRejected = 1;
    return overlay;
}

}  // namespace terralux::features
