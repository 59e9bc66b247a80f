#version 450
#extension GL_GOOGLE_include_directive : require
// Terrain shading (docs/lighting.md) and the debug views. It binds the view and the lights only: probe
// light comes in per vertex from the probe pass, when there is one. Built four times: with
// TLX_SHADOWS the lights include the sun's shadow cascades, with TLX_REFLECTIONS the reflection
// probes; each of the four again with TLX_LPV binds the set of the LPV and the local lights
// (lpv.glsl), read as its specialisation constants say.
#include "blocks/glsl.h"
#include "blocks/camera.h"
#include "blocks/surface.h"
#include "blocks/sun_sky.h"
#include "blocks/atmosphere.h"
#ifdef TLX_LPV
#include "blocks/lpv.h"
#endif
#include "sh.glsl"
#include "sky.glsl"
#include "brdf.glsl"
#include "surface.glsl"
#include "tonemap.glsl"
#include "shadows.glsl"
#include "fog.glsl"
#include "reflections.glsl"
#include "lpv.glsl"
#include "views.glsl"

layout(location = 0) in vec3 worldPos;
layout(location = 1) in vec3 worldNormal;
layout(location = 2) in vec4 probeIrradianceWeight;  // ShadingPoint.probe
layout(location = 0) out vec4 outColor;

void main() {
    ShadingPoint s;
    s.position = worldPos;
    s.probe = probeIrradianceWeight;
    // Every map read comes first, in uniform control flow, so the hardware's derivatives (mip
    // selection) hold. Off the footprint (the skirt) the mesh normal and open sky stand.
    vec2 t = footprintT(worldPos);
    bool inside = onFootprint(t);
    vec2 uv = surfaceUv(t, surface.normalAoMapSize);
    // The normal map's level by the Vulkan spec's formula (λ = log2 ρmax, ρ the length of the
    // texel-space derivative along x and along y), from fine derivatives, not each driver's
    // approximation of it: the normal variance (Toksvig) is the filtered normal's shortening,
    // which the level sets, and drivers differ in the level they pick (normalMapLod, surface.glsl).
    vec4 normalAo = textureLod(surfaceNormalAo, uv, normalMapLod(uv * surface.normalAoMapSize));
    float coarseAo = surface.probeAoLevel > 0.0 ? textureLod(surfaceNormalAo, uv, surface.probeAoLevel).w : normalAo.w;
    // Maps a frame does not read are not sampled (the conditions are uniform, so the derivatives
    // still hold): on a CPU rasteriser each trilinear lookup is a real cost.
    vec3 mapAlbedo = surface.albedoFromMap > 0.5 ? texture(surfaceAlbedoMap, surfaceUv(t, surface.albedoMapSize)).rgb : vec3(1.0);
    s.filled = inside && camera.debugView == kViewFilled ? texture(surfaceFilled, uv).r : 0.0;
    float pixelMetres = length(fwidth(worldPos));
    s.faceNormal = faceNormal(worldPos, worldNormal);
    s.vertexNormal = normalize(worldNormal);
    float distance = length(worldPos - camera.position);

    float meanLength = length(normalAo.xyz);
    vec3 base = inside && meanLength > 1e-4 ? normalAo.xyz / meanLength : normalize(worldNormal);
    s.variance = inside ? toksvigVariance(meanLength) : 0.0;
    s.aoRaw = inside ? normalAo.w : 1.0;
    s.ao = surface.aoOnSky > 0.5 ? s.aoRaw : 1.0;
    // Probes already hold the occlusion at their own spacing: only the AO finer than that (the
    // ratio to the AO filtered to the probes' scale) darkens their light (docs/lighting.md).
    float finer = clamp(s.aoRaw / max(coarseAo, 1e-3), 0.0, 1.0);
    s.aoProbe = inside && surface.probeAoLevel > 0.0 ? mix(1.0, finer, surface.aoOnProbes) : 1.0;
    float amount = detailAmount(distance, pixelMetres);
    s.normal = amount > 0.0 ? detailNormal(base, worldPos, amount) : base;
    float r = surface.roughness;
    s.roughness = max(surface.specularAA > 0.5 ? widenedRoughness(r, s.variance) : r, surface.roughnessFloor);
    s.albedo = (surface.albedoFromMap > 0.5 ? mapAlbedo : surface.albedo) * albedoVariation(worldPos.xz, pixelMetres);
    outColor = vec4(shadeView(camera.debugView, s), 1.0);
}
