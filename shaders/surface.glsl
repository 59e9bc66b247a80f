// The terrain's surface maps and the procedural micro-detail (docs/lighting.md, "Surface"); include
// after blocks/surface.h and sh.glsl.
#ifndef TLX_SURFACE_GLSL
#define TLX_SURFACE_GLSL

layout(set = TLX_SET_VIEW, binding = TLX_SURFACE_NORMAL_AO_BINDING) uniform sampler2D surfaceNormalAo;
layout(set = TLX_SET_VIEW, binding = TLX_SURFACE_ALBEDO_BINDING) uniform sampler2D surfaceAlbedoMap;
layout(set = TLX_SET_VIEW, binding = TLX_SURFACE_FILLED_BINDING) uniform sampler2D surfaceFilled;

// Position across the footprint, [0, 1] on each axis inside it.
vec2 footprintT(vec3 p) { return (p.xz - surface.footprintMin) * surface.invFootprintSpan; }
bool onFootprint(vec2 t) { return all(greaterThanEqual(t, vec2(-1e-4))) && all(lessThanEqual(t, vec2(1.0 + 1e-4))); }
// Texel centres span the footprint corner to corner (SurfaceMaps.h).
vec2 surfaceUv(vec2 t, vec2 size) { return (clamp(t, 0.0, 1.0) * (size - 1.0) + 0.5) / size; }

// The mip level of a texture read at texel-space position `texel`: the spec's λ = log2(ρmax) with
// ρx = |∂texel/∂x| and ρy = |∂texel/∂y| taken from fine derivatives, and no level below 0 (a
// conformant driver may approximate ρ, and a CPU and a GPU driver do differently).
float normalMapLod(vec2 texel) {
    vec2 dx = dFdxFine(texel), dy = dFdyFine(texel);
    return max(0.5 * log2(max(max(dot(dx, dx), dot(dy, dy)), 1e-12)), 0.0);
}

// Normal variance from the shortening of a filtered mean normal (Toksvig 2005): σ² = (1 − |N̄|)/|N̄|.
float toksvigVariance(float meanLength) {
    float len = clamp(meanLength, 1e-4, 1.0);
    return (1.0 - len) / len;
}
// Roughness² is the microfacets' slope variance (Olano & Baker 2010); the normals' variance adds
// to it, and (1 − r²) keeps r' <= 1. Mirrors widenedRoughness() in SurfaceMaps.cpp.
float widenedRoughness(float r, float variance) {
    float r2 = r * r;
    return sqrt(min(r2 + max(variance, 0.0) * (1.0 - r2), 1.0));
}

// Integer hash of a lattice point (pcg2d, Jarzynski & Olano 2020): no sin(), so it holds at
// UTM-sized coordinates where a float hash repeats.
vec2 latticeGradient(ivec2 cell) {
    uvec2 v = uvec2(cell) * 1664525u + 1013904223u;
    v.x += v.y * 1664525u;
    v.y += v.x * 1664525u;
    v ^= v >> 16u;
    v.x += v.y * 1664525u;
    v.y += v.x * 1664525u;
    v ^= v >> 16u;
    float a = float(v.x & 0xffffu) * (2.0 * PI / 65536.0);
    return vec2(cos(a), sin(a));
}

// Gradient noise with its analytic derivatives (quintic fade; Perlin 2002): x value in about
// [-0.7, 0.7], yz d/dp.
vec3 gradientNoise(vec2 p) {
    vec2 fl = floor(p);
    ivec2 i = ivec2(fl);
    vec2 f = p - fl;
    vec2 u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    vec2 du = 30.0 * f * f * (f * (f - 2.0) + 1.0);
    vec2 ga = latticeGradient(i), gb = latticeGradient(i + ivec2(1, 0));
    vec2 gc = latticeGradient(i + ivec2(0, 1)), gd = latticeGradient(i + ivec2(1, 1));
    float va = dot(ga, f), vb = dot(gb, f - vec2(1.0, 0.0));
    float vc = dot(gc, f - vec2(0.0, 1.0)), vd = dot(gd, f - vec2(1.0, 1.0));
    float k = va - vb - vc + vd;
    float value = va + u.x * (vb - va) + u.y * (vc - va) + u.x * u.y * k;
    vec2 d = ga + u.x * (gb - ga) + u.y * (gc - ga) + u.x * u.y * (ga - gb - gc + gd) +
             du * (u.yx * k + vec2(vb, vc) - va);
    return vec3(value, d);
}

// The detail bump's tangent-space normal on one projection plane: two octaves of gradient noise,
// one repeat per `scale` metres, as a height field of slope `strength`.
vec3 detailBump(vec2 p, float scale, float strength) {
    vec3 a = gradientNoise(p / scale);
    vec3 b = gradientNoise(p / scale * 2.7 + 17.0);
    // Height = scale × strength × noise, so the slope is strength × d(noise)/d(p/scale).
    vec2 slope = strength * (a.yz + 0.5 * 2.7 * b.yz);
    return normalize(vec3(-slope, 1.0));
}

// Reoriented normal mapping (Barré-Brisebois & Hill 2012) of a detail normal onto a base normal,
// both in the base's tangent frame with z along the projection axis.
vec3 reorient(vec3 base, vec3 detailN) {
    base += vec3(0.0, 0.0, 1.0);
    detailN *= vec3(-1.0, -1.0, 1.0);
    return base * dot(base, detailN) / base.z - detailN;
}

// The base normal with the tiling detail, projected along the three axes and blended by the
// normal (triplanar, so steep faces are not stretched; the RNM-per-plane form of Golus 2017).
// `amount` in [0, 1] scales the detail's slope: 0 returns the base normal.
vec3 detailNormal(vec3 n, vec3 p, float amount) {
    float scale = surface.detailScale, strength = surface.detailStrength * amount;
    vec3 an = abs(n);
    vec3 w = an * an;
    w *= w;
    w /= (w.x + w.y + w.z);
    vec3 tx = reorient(vec3(n.zy, an.x), detailBump(p.zy, scale, strength));
    vec3 ty = reorient(vec3(n.xz, an.y), detailBump(p.xz, scale, strength));
    vec3 tz = reorient(vec3(n.xy, an.z), detailBump(p.xy, scale, strength));
    tx.z *= sign(n.x) == 0.0 ? 1.0 : sign(n.x);
    ty.z *= sign(n.y) == 0.0 ? 1.0 : sign(n.y);
    tz.z *= sign(n.z) == 0.0 ? 1.0 : sign(n.z);
    return normalize(tx.zyx * w.x + ty.xzy * w.y + tz.xyz * w.z);
}

// How much of the detail shows: full near the camera, none at detail.z metres, linear between so
// nothing pops; and none where a pixel spans more than a quarter of a repeat, where it would only
// alias into sparkle.
float detailAmount(float distance, float pixelMetres) {
    if (surface.detailStrength <= 0.0 || surface.detailFade <= 0.0) return 0.0;
    float fade = clamp(1.0 - distance / surface.detailFade, 0.0, 1.0);
    float resolved = clamp(2.0 - pixelMetres * 8.0 / surface.detailScale, 0.0, 1.0);
    return fade * resolved;
}

// Procedural albedo variation: a multiplier in [1 − v, 1 + v] from gradient noise over 64 m and
// 9 m (the finer octave fades where pixels are too large to resolve it).
float albedoVariation(vec2 xz, float pixelMetres) {
    float v = surface.albedoVariation;
    if (v <= 0.0) return 1.0;
    float coarse = gradientNoise(xz / 64.0 + 31.0).x;
    float fine = gradientNoise(xz / 9.0 - 57.0).x * clamp(2.0 - pixelMetres * 8.0 / 9.0, 0.0, 1.0);
    return 1.0 + v * clamp((0.65 * coarse + 0.35 * fine) * 1.4, -1.0, 1.0);
}

#endif
