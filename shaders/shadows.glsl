// Sun shadows from the cascades (docs/lighting.md, "Shadows"). Built with TLX_SHADOWS the terrain
// binds the cascades' maps; without, the sun is unshadowed and no cascade covers any point.
// Include after blocks/camera.h, blocks/sun_sky.h and sh.glsl.
#ifndef TLX_SHADOWS_GLSL
#define TLX_SHADOWS_GLSL

#ifdef TLX_SHADOWS
#include "blocks/shadows.h"
layout(set = TLX_SET_LIGHTS, binding = TLX_SHADOW_MAP_COMPARE_BINDING) uniform sampler2DArrayShadow shadowCompare;
layout(set = TLX_SET_LIGHTS, binding = TLX_SHADOW_MAP_DEPTH_BINDING) uniform sampler2DArray shadowDepth;

const int kFilterPcss = 0, kFilterPcf = 1, kFilterHard = 2;
const int kBlockerTaps = 16, kFilterTaps = 24;
// Largest PCSS search and filter radius, texels: bounds the cost at grazing suns, where the
// penumbra of a distant ridge spans more of the map than a kernel can sample.
const float kMaxKernelTexels = 24.0;

// The cascade whose slice holds p (by view depth), -1 beyond the shadow distance.
int sunCascade(vec3 p) {
    float d = dot(p - camera.position, shadow.forward);
    for (int i = 0; i < shadow.cascadeCount; ++i)
        if (d <= shadow.ends[i]) return i;
    return -1;
}

// Interleaved gradient noise (Jimenez 2014, "Next Generation Post Processing in Call of Duty:
// Advanced Warfare"): a per-pixel rotation of the taps, so banding turns into fine noise.
float shadowNoise() { return fract(52.9829189 * fract(dot(gl_FragCoord.xy, vec2(0.06711056, 0.00583715)))); }

// Tap i of n on a golden-angle (Vogel) spiral in the unit disc: evenly spread, blue-noise-like
// taps without a table (an indexed constant array costs a CPU driver per fragment).
vec2 spiralTap(int i, int n, float rotation) {
    float r = sqrt((float(i) + 0.5) / float(n));
    float a = float(i) * 2.39996323 + rotation * 6.28318531;
    return r * vec2(cos(a), sin(a));
}

// Fernando 2005, "Percentage-Closer Soft Shadows": a blocker search over the region the sun's disc
// can be hidden from, the penumbra from the mean blocker distance, then PCF over it. For the sun
// the light size is its angular radius: a blocker Δ metres toward the sun casts a penumbra of
// half-width Δ·tan(radius), converted to the cascade's texels.
float sunShadow(vec3 p, vec3 n) {
    int c = sunCascade(p);
    if (c < 0) return dot(n, sunSky.sunDirection) > 0.0 ? 1.0 : 0.0;
    vec3 l = normalize(sunSky.sunDirection);
    // A surface facing away from the sun does not see it (as the traced visibility has it).
    float ndotl = dot(n, l);
    if (ndotl <= 0.0) return 0.0;
    float texelWorld = shadow.texel[c];
    // Normal offset grows as the surface turns from the sun (slopes facing away need more).
    vec3 q = p + n * (shadow.normalBias * texelWorld * sqrt(1.0 - ndotl * ndotl)) + l * (shadow.depthBias * texelWorld);
    vec4 lc = shadow.lightViewProj[c] * vec4(q, 1.0);
    vec2 uv = lc.xy * 0.5 + 0.5;
    float z = lc.z;
    float layer = float(c);
    if (shadow.filterMode == kFilterHard) return texture(shadowCompare, vec4(uv, layer, z));
    float texelUv = 1.0 / shadow.mapResolution;
    float rotation = shadowNoise();
    float radiusTexels = 1.5;
    if (shadow.filterMode == kFilterPcss) {
        float tanR = shadow.tanSunRadius;
        // Blocker search: the widest penumbra comes from a blocker at the map's near plane.
        float searchTexels = clamp(z * shadow.depthRange[c] * tanR / texelWorld, 1.0, kMaxKernelTexels);
        float blockers = 0.0, blockerDepth = 0.0;
        for (int i = 0; i < kBlockerTaps; ++i) {
            vec2 o = spiralTap(i, kBlockerTaps, rotation) * searchTexels * texelUv;
            float d = texture(shadowDepth, vec3(uv + o, layer)).r;
            if (d < z) {
                blockers += 1.0;
                blockerDepth += d;
            }
        }
        if (blockers == 0.0) return 1.0;
        float gap = (z - blockerDepth / blockers) * shadow.depthRange[c];  // metres to the blockers
        radiusTexels = clamp(gap * tanR / texelWorld, 0.5, kMaxKernelTexels);
    }
    float lit = 0.0;
    for (int i = 0; i < kFilterTaps; ++i) {
        vec2 o = spiralTap(i, kFilterTaps, rotation) * radiusTexels * texelUv;
        lit += texture(shadowCompare, vec4(uv + o, layer, z));
    }
    return lit / float(kFilterTaps);
}

// Whether p lies within about a pixel of the boundary between two cascades (or of the shadow
// distance), for the cascade overlay.
bool nearCascadeBoundary(vec3 p) {
    float d = dot(p - camera.position, shadow.forward);
    float w = 1.5 * fwidth(d);
    for (int i = 0; i < shadow.cascadeCount; ++i)
        if (abs(d - shadow.ends[i]) < w) return true;
    return false;
}
#else
float sunShadow(vec3 p, vec3 n) { return dot(n, sunSky.sunDirection) > 0.0 ? 1.0 : 0.0; }
int sunCascade(vec3 p) { return -1; }
bool nearCascadeBoundary(vec3 p) { return false; }
#endif

#endif
