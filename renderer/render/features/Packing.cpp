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
    camera.position = glm::vec4(s.camera.position(), s.camera.planes(extent).farPlane);
    camera.viewport = glm::vec4(float(s.width), float(s.height), 1.0f / float(s.width), 1.0f / float(s.height));
    // What the per-vertex attribute holds: 2 the traced sun visibility, 1 the probe diagnostics,
    // 0 probe light.
    camera.view = glm::ivec4(s.debugView, s.linearOutput ? 1 : 0,
                             view.needs.sunVisibility ? 2 : view.needs.probeDiagnostics ? 1 : 0, 0);
    return camera;
}

blocks::CameraBlock packMirroredCamera(const RenderSettings& s, const blocks::CameraBlock& camera, float extent,
                                       float level, float width, float height) {
    const float aspect = float(s.width) / float(s.height);
    blocks::CameraBlock mirrored = camera;
    mirrored.viewProj = s.camera.reflectedViewProjection(aspect, extent, level);
    mirrored.invViewProj = glm::inverse(mirrored.viewProj);
    mirrored.position = glm::vec4(s.camera.reflectedPosition(level), camera.position.w);
    mirrored.viewport = glm::vec4(width, height, 1.0f / width, 1.0f / height);
    mirrored.view = glm::ivec4(kViewBeauty, 1, camera.view.z, 0);
    return mirrored;
}

blocks::SurfaceBlock packSurface(const RenderSettings& s, const SurfaceInputs& in) {
    blocks::SurfaceBlock surface;
    surface.albedo = glm::vec4(s.albedo, in.albedoMap ? 1.0f : 0.0f);
    surface.material = glm::vec4(float(s.terrain.roughness), s.exposure, s.terrain.specularAA ? 1.0f : 0.0f,
                                 float(kRoughnessFloor));
    surface.footprint = glm::vec4(in.footprintMin, in.footprintSpan.x > 0.0f ? 1.0f / in.footprintSpan.x : 0.0f,
                                  in.footprintSpan.y > 0.0f ? 1.0f / in.footprintSpan.y : 0.0f);
    surface.mapSizes = glm::vec4(in.normalAoMapSize, in.albedoMapSize);
    surface.ao = glm::vec4(s.ao.enabled && in.ao ? 1.0f : 0.0f, s.ao.enabled ? float(s.ao.strength) : 0.0f,
                           in.probeAoLevel, 0.0f);
    const DetailSettings& d = s.detail;
    surface.detail = d.enabled ? glm::vec4(float(d.normalStrength), float(d.scale), float(d.fadeDistance),
                                           float(d.albedoVariation))
                               : glm::vec4(0.0f, 1.0f, 0.0f, 0.0f);
    return surface;
}

blocks::SunSkyBlock packSunSky(const RenderSettings& s) {
    blocks::SunSkyBlock sunSky;
    sunSky.sunDirection = glm::vec4(s.sun.direction, s.sun.angularRadius);
    sunSky.sunIlluminance = glm::vec4(s.sun.illuminance, 0.0f);
    for (int k = 0; k < 9; ++k) sunSky.skySh[k] = glm::vec4(s.skySh.c[size_t(k)], 0.0f);
    return sunSky;
}

blocks::AtmosphereBlock packAtmosphere(const FogSettings& fog) {
    blocks::AtmosphereBlock atmosphere;
    atmosphere.fog = glm::vec4(float(fog.density), float(fog.scaleHeight > 0.0 ? 1.0 / fog.scaleHeight : 0.0),
                               float(fog.baseHeight.value_or(0.0)), float(fog.anisotropy));
    atmosphere.fogColor = glm::vec4(fog.color.value_or(glm::vec3(0.0f)), float(fog.inscatter));
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
    block.forward = glm::vec4(glm::normalize(s.camera.target - s.camera.position()), float(range.nearDistance));
    block.bias = glm::vec4(float(s.shadows.depthBias), float(s.shadows.normalBias), std::tan(s.sun.angularRadius),
                           float(resolution));
    block.mode = glm::ivec4(int(cascades.size()), int(s.shadows.filter), 0, 0);
    return block;
}

blocks::WaterBlock packWater(const RenderSettings& s, const WaterInputs& in) {
    const WaterSettings& ws = s.water;
    blocks::WaterBlock block;
    block.plane = glm::vec4(in.level, float(s.time), in.shoreFadeDistance, ws.depthAware ? 1.0f : 0.0f);
    block.scatter = glm::vec4(ws.color, float(ws.roughness));
    block.absorption = glm::vec4(ws.absorption, ws.reflection == WaterReflection::Planar ? 1.0f : 0.0f);
    const size_t waves = std::min<size_t>(ws.waves.size(), WaterSettings::kMaxWaves);
    block.look = glm::vec4(float(ws.distortion), float(waves), in.fieldSize);
    block.mesh = glm::vec4(in.meshSpacing, 0.0f, 0.0f, 0.0f);
    for (size_t i = 0; i < waves; ++i) {
        const water::WaveTerms wave = water::waveTerms(ws.waves[i]);
        block.waves[i] = glm::vec4(float(wave.direction.x), float(wave.direction.y), float(wave.k), float(wave.amplitude));
        block.phases[i] = glm::vec4(float(wave.omegaDeep), float(wave.phase), 0.0f, 0.0f);
    }
    return block;
}

std::vector<blocks::LocalLightRecord> packLocalLights(const std::vector<LocalLight>& lights, bool used) {
    std::vector<blocks::LocalLightRecord> records(std::max<size_t>(used ? lights.size() : 0, 1));
    for (size_t i = 0; used && i < lights.size(); ++i) {
        const LocalLight& l = lights[i];
        blocks::LocalLightRecord& r = records[i];
        const bool spot = l.type == LocalLightType::Spot;
        r.positionRange = glm::vec4(l.position, float(l.range));
        r.emitted = glm::vec4(l.color * float(l.intensity), spot ? 1.0f : 0.0f);
        const float len = glm::length(l.direction);
        r.direction = glm::vec4(len > 0.0f ? l.direction / len : glm::vec3(0.0f, -1.0f, 0.0f), 0.0f);
        const float cosOuter = std::cos(glm::radians(float(l.outerConeDeg)));
        const float cosInner = std::cos(glm::radians(float(l.innerConeDeg)));
        r.cone = glm::vec4(cosOuter, 1.0f / std::max(0.001f, cosInner - cosOuter), 0.0f, 0.0f);
    }
    return records;
}

blocks::OverlayBlock packOverlay(const RenderSettings& s, float smallestLeaf, float smallestLeafPixels) {
    blocks::OverlayBlock overlay;
    overlay.leaves = glm::vec4(smallestLeaf, smallestLeafPixels, 0.0f, 0.0f);
    overlay.markers = glm::ivec4(s.showProbePositions ? 1 : 0, 1, 0, 0);
    return overlay;
}

}  // namespace terralux::features
