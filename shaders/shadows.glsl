// Sun shadows from the cascades (docs/lighting.md, "Shadows"). Built with TLX_SHADOWS the terrain
// binds the cascades' maps; without, the sun is unshadowed and no cascade covers any point.
// Include after blocks/camera.h, blocks/sun_sky.h and sh.glsl.
#ifndef TLX_SHADOWS_GLSL
#define TLX_SHADOWS_GLSL

// The normal of the triangle under the fragment, turned to the side of `n`: position derivatives
// are constant across a triangle (helper lanes extend its plane). Call in uniform control flow.
vec3 faceNormal(vec3 p, vec3 n) {
    vec3 f = cross(dFdx(p), dFdy(p));
    float len = length(f);
    if (!(len > 1e-20)) return normalize(n);
    f /= len;
    return dot(f, n) < 0.0 ? -f : f;
}

#ifdef TLX_SHADOWS
#include "blocks/shadows.h"
#include "shadow_math.glsl"
layout(set = TLX_SET_LIGHTS, binding = TLX_SHADOW_MAP_DEPTH_BINDING) uniform sampler2DArray shadowDepth;

// The terrain's own shadow where a cascade cannot draw the relief (shadowTakesHorizon): the
// sun's visible share at every vertex of the DEM, from its horizon in the sun's azimuth
// (renderer/terrain/HorizonAO.h, sunHorizonVisibility), interpolated between the vertices. Only the
// terrain reads it (surface.glsl's footprint): water and anything above the surface see more of
// the sun than the ground under them, and keep the maps (TLX_SHADOW_MAPS_ONLY).
#ifndef TLX_SHADOW_MAPS_ONLY
layout(std430, set = TLX_SET_LIGHTS, binding = TLX_SUN_HORIZON_BINDING) readonly buffer SunHorizon {
    uint sunHorizonBytes[];
};
float sunHorizonAt(ivec2 v) {
    int k = v.y * shadow.horizonWidth + v.x;
    return float((sunHorizonBytes[k >> 2] >> uint(8 * (k & 3))) & 0xffu) * (1.0 / 255.0);
}
float horizonShadow(vec3 p) {
    ivec2 size = ivec2(shadow.horizonWidth, shadow.horizonHeight);
    vec2 q = clamp(footprintT(p), 0.0, 1.0) * vec2(size - 1);
    ivec2 i = min(ivec2(q), max(size - 2, ivec2(0)));
    vec2 f = q - vec2(i);
    ivec2 j = min(i + 1, size - 1);
    // Across the cell's two triangles, split along the bake's diagonal (Heightfield::surfaceHeight),
    // as the mesh interpolates what it carries per vertex.
    float v00 = sunHorizonAt(i), v11 = sunHorizonAt(j);
    return f.x <= f.y ? v00 + f.y * (sunHorizonAt(ivec2(i.x, j.y)) - v00) + f.x * (v11 - sunHorizonAt(ivec2(i.x, j.y)))
                      : v00 + f.x * (sunHorizonAt(ivec2(j.x, i.y)) - v00) + f.y * (v11 - sunHorizonAt(ivec2(j.x, i.y)));
}
#define TLX_HORIZON_FROM shadow.horizonFrom
#else
float horizonShadow(vec3 p) { return 1.0; }
#define TLX_HORIZON_FROM shadow.cascadeCount
#endif

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

// Taps on a golden-angle (Vogel) spiral in the unit disc: evenly spread, blue-noise-like taps
// without a table (an indexed constant array costs a CPU driver per fragment). Tap i lies at
// radius sqrt((i + ½)/n) and angle i·g + 2π·rotation, g the golden angle; the angle's cosine and
// sine step from tap to tap by one rotation through g (the angle-sum identities), so a tap costs a
// square root instead of a cosine and a sine.
const vec2 kGoldenStep = vec2(-0.73736888, 0.67549029);  // cos g, sin g; g = π(3 − √5)
vec2 spiralStart(float rotation) { return vec2(cos(rotation * 6.28318531), sin(rotation * 6.28318531)); }
vec2 spiralNext(vec2 d) { return vec2(d.x * kGoldenStep.x - d.y * kGoldenStep.y, d.x * kGoldenStep.y + d.y * kGoldenStep.x); }
float spiralRadius(int i, int n) { return sqrt((float(i) + 0.5) / float(n)); }

// The receiver's plane in cascade c's clip space: dz/du and dz/dv of the plane through the point
// with geometric normal ng (Isidoro 2006, "Shadow Mapping: GPU-based Tips and Techniques",
// receiver plane depth bias). The projection is affine, so a world displacement d moves clip space
// by A·d (A its linear part); d in the plane has ng·d = 0, i.e. m·Δclip = 0 with m = A^-T·ng,
// so Δz = −(m.x·Δx + m.y·Δy)/m.z and Δx = 2Δu, Δy = 2Δv. The slope is capped at
// kMaxReceiverSlope (the plane's rise per metre across the light, about 87°): a plane nearly
// parallel to the sun gives no bound, and faces that steep are turned away or at the terminator.
const float kMaxReceiverSlope = 20.0;
// The depth allowed below the plane is shadowSlopeTexels() texels of its slope (shadow_math.glsl).
vec2 receiverPlane(int c, vec3 ng) {
    vec3 m = inverse(transpose(mat3(shadow.lightViewProj[c]))) * ng;
    vec2 g = -2.0 * m.xy / (abs(m.z) > 1e-12 ? m.z : 1e-12);
    // kMaxReceiverSlope metres of depth per metre across the map, in z per unit of uv.
    float texelUv = 1.0 / shadow.mapResolution;
    float cap = kMaxReceiverSlope * shadow.texel[c] / (shadow.depthRange[c] * texelUv);
    float len = length(g);
    return len > cap ? g * (cap / len) : g;
}

// The 2×2 map texels around uv, as a bilinear depth-compare lookup reads them, but each compared
// with the receiver's plane at that texel's own centre: their depths (textureGather's order: texel
// (0,1), (1,1), (1,0), (0,0)), the plane's depth at their centres, and uv's bilinear weights.
struct TexelQuad {
    vec4 depth, plane, weight;
};
TexelQuad texelQuad(vec2 uv, float layer, float z, vec2 plane) {
    float res = shadow.mapResolution;
    vec2 st = uv * res - 0.5;
    vec2 i = floor(st);
    vec2 f = st - i;
    TexelQuad t;
    t.depth = textureGather(shadowDepth, vec3((i + 1.0) / res, layer));
    vec2 lo = -f / res, hi = (1.0 - f) / res;  // the texel centres' offsets from uv
    t.plane = z + vec4(dot(plane, vec2(lo.x, hi.y)), dot(plane, hi), dot(plane, vec2(hi.x, lo.y)), dot(plane, lo));
    t.weight = vec4((1.0 - f.x) * f.y, f.x * f.y, f.x * (1.0 - f.y), (1.0 - f.x) * (1.0 - f.y));
    return t;
}
float litFraction(TexelQuad t) { return dot(t.weight, step(t.plane, t.depth)); }

// Fernando 2005, "Percentage-Closer Soft Shadows": a blocker search over the region the sun's disc
// can be hidden from, the penumbra from the mean blocker distance, then PCF over it. For the sun
// the light size is its angular radius: a blocker Δ metres toward the sun casts a penumbra of
// half-width Δ·tan(radius), converted to the cascade's texels. Every texel is compared with the
// receiver's own plane at that texel (receiverPlane, texelQuad): a kernel wider than a texel, on a
// receiver tilted to the sun, would otherwise find the receiver itself in front of the point:
// acne that grows with the kernel and as the sun sinks, which no constant bias removes without
// also losing the shadows of low relief.
// The lit fraction of p from cascade c's map. p: the point; ng: the normal of the drawn triangle,
// the surface the maps hold; l: toward the sun. `partner`: -1 where p falls outside the map (the
// next cascade's light-space box need not reach back into the slice before its own).
float cascadeShadow(int c, vec3 p, vec3 ng, vec3 l, float rotation, bool partner) {
    float texelWorld = shadow.texel[c];
    // Normal offset grows as the surface turns from the sun (slopes facing away need more).
    float ngdotl = clamp(dot(ng, l), -1.0, 1.0);
    vec3 q = p + ng * (shadow.normalBias * texelWorld * sqrt(1.0 - ngdotl * ngdotl)) + l * (shadow.depthBias * texelWorld);
    vec4 lc = shadow.lightViewProj[c] * vec4(q, 1.0);
    vec2 uv = lc.xy * 0.5 + 0.5;
    if (partner && (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))))) return -1.0;
    float texelUv = 1.0 / shadow.mapResolution;
    vec2 plane = receiverPlane(c, ng);
    float z = lc.z - shadowSlopeTexels() * (abs(plane.x) + abs(plane.y)) * texelUv;
    float layer = float(c);
    int filterMode = camera.shadowFilter >= 0 ? camera.shadowFilter : shadow.filterMode;
    if (filterMode == kFilterHard) return litFraction(texelQuad(uv, layer, z, plane));
    float radiusTexels = 1.5;
    if (filterMode == kFilterPcss) {
        float tanR = shadow.tanSunRadius;
        // Blocker search: the widest penumbra comes from a blocker at the map's near plane.
        float searchTexels = clamp(z * shadow.depthRange[c] * tanR / texelWorld, 1.0, kMaxKernelTexels);
        float blockers = 0.0, gaps = 0.0;
        vec2 dir = spiralStart(rotation);
        for (int i = 0; i < kBlockerTaps; ++i, dir = spiralNext(dir)) {
            vec2 o = dir * (spiralRadius(i, kBlockerTaps) * searchTexels * texelUv);
            TexelQuad t = texelQuad(uv + o, layer, z + dot(plane, o), plane);
            vec4 blocked = vec4(lessThan(t.depth, t.plane));
            blockers += dot(blocked, vec4(1.0));
            gaps += dot(blocked, t.plane - t.depth);
        }
        if (blockers == 0.0) return 1.0;
        // Every texel the search read is a blocker: the point is in umbra. The filter reads within
        // the search's region (its radius, set by the blockers' distance, is at most the search's),
        // where 16 spread taps found no light, so it would find little or none; skipping it saves
        // its 24 taps wherever the shadow is full (the render tests' agreement with the traced sun
        // is unchanged by it).
        if (blockers == float(4 * kBlockerTaps)) return 0.0;
        float gap = gaps / blockers * shadow.depthRange[c];  // metres to the blockers
        radiusTexels = clamp(gap * tanR / texelWorld, 0.5, kMaxKernelTexels);
    }
    float lit = 0.0;
    vec2 dir = spiralStart(rotation);
    for (int i = 0; i < kFilterTaps; ++i, dir = spiralNext(dir)) {
        vec2 o = dir * (spiralRadius(i, kFilterTaps) * radiusTexels * texelUv);
        lit += litFraction(texelQuad(uv + o, layer, z + dot(plane, o), plane));
    }
    return lit / float(kFilterTaps);
}

// The cascade after c, or -1 after the last (the unshadowed sun beyond the shadow distance).
int nextCascade(int c) { return c + 1 < shadow.cascadeCount ? c + 1 : -1; }

// The weight of what follows cascade c at p in its slice: 0 before the blend band, rising
// smoothly to 1 at the slice's end. After the last cascade follows the unshadowed sun where
// terrain lies beyond the shadow distance (shadow.fadeOut), else nothing (weight 0).
float cascadeBlendWeight(vec3 p, int c) {
    if (c < 0 || shadow.cascadeBlend <= 0.0 || (nextCascade(c) < 0 && shadow.fadeOut <= 0.0)) return 0.0;
    float d = dot(p - camera.position, shadow.forward);
    float begin = c == 0 ? shadow.nearDepth : shadow.ends[c - 1], end = shadow.ends[c];
    return smoothstep(end - shadow.cascadeBlend * (end - begin), end, d);
}

// Over the far shadows.cascade_blend of its slice, a cascade's shadow blends into the next one's
// (smoothstep in view depth), so the step in texel size and penumbra is no seam (the transition
// band of Engel, "Cascaded Shadow Maps", ShaderX5, 2006). The last cascade blends the same way
// into the unshadowed sun where the shadow distance ends before the terrain, so that end is no
// line across the view either.
// n: the shading normal (which side of the terminator p is on).
float sunShadow(vec3 p, vec3 n, vec3 ng) {
    int c = sunCascade(p);
    if (c < 0) return dot(n, sunSky.sunDirection) > 0.0 ? 1.0 : 0.0;
    vec3 l = normalize(sunSky.sunDirection);
    // A surface facing away from the sun does not see it (as the traced visibility has it).
    if (dot(n, l) <= 0.0) return 0.0;
    float rotation = shadowNoise();
    // From cascade TLX_HORIZON_FROM on the horizon map stands in for the maps; a cascade before
    // it blends into the map over its band as into the next cascade.
    int from = TLX_HORIZON_FROM;
    float lit = c >= from ? horizonShadow(p) : cascadeShadow(c, p, ng, l, rotation, false);
    float t = cascadeBlendWeight(p, c);
    float next = t <= 0.0 ? -1.0
               : nextCascade(c) < 0 ? 1.0
               : c + 1 >= from ? horizonShadow(p)
               : cascadeShadow(c + 1, p, ng, l, rotation, true);
    return next >= 0.0 ? mix(lit, next, t) : lit;
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
float sunShadow(vec3 p, vec3 n, vec3 ng) { return dot(n, sunSky.sunDirection) > 0.0 ? 1.0 : 0.0; }
float cascadeBlendWeight(vec3 p, int c) { return 0.0; }
int nextCascade(int c) { return -1; }
int sunCascade(vec3 p) { return -1; }
bool nearCascadeBoundary(vec3 p) { return false; }
#endif

#endif
