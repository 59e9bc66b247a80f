// The light propagation volumes as the terrain reads them, and the local lights' direct light
// (docs/lighting.md, "Light propagation volumes"). Include after blocks/glsl.h, blocks/lpv.h,
// sh.glsl and brdf.glsl. Every function mirrors renderer/lpv/Lpv.cpp (Volumes::evaluate and its
// helpers) step for step: the render tests compare the two at the same points. The shaders built
// with TLX_LPV bind the set; whether a frame reads the LPV or the lights are specialisation
// constants, so each compiles out what the frame does not use.
#ifndef TLX_LPV_GLSL
#define TLX_LPV_GLSL
#include "display_math.glsl"

struct LpvSample {
    vec3 irradiance;  // × indirect_intensity
    vec3 specular;    // quality 2: radiance along the mirror direction, × indirect_intensity
};

// Without TLX_LPV the shader declares none of the set: the pipelines of frames without the LPV
// and lights keep the layout they had.
#ifndef TLX_LPV
const bool kLpv = false;
const bool kLocalLights = false;
#else
layout(constant_id = 1) const int kLpvEnabled = 0;
layout(constant_id = 2) const int kLocalLightsEnabled = 0;
const bool kLpv = kLpvEnabled != 0;
const bool kLocalLights = kLocalLightsEnabled != 0;

layout(set = TLX_SET_SUBSYSTEM, binding = TLX_LPV_LIGHT_BINDING, std430) readonly buffer LpvLight { vec4 v[]; } lpvLight;
layout(set = TLX_SET_SUBSYSTEM, binding = TLX_LPV_GEOMETRY_BINDING, std430) readonly buffer LpvGeometry { vec4 v[]; } lpvGeometry;
layout(set = TLX_SET_SUBSYSTEM, binding = TLX_LOCAL_LIGHTS_BINDING, std430) readonly buffer LocalLights { LocalLightRecord l[]; } localLights;

const int kLpvGrid = 32;
const int kLpvCorners = 33;
const int kLpvCells = kLpvGrid * kLpvGrid * kLpvGrid;
const int kLpvCornerCount = kLpvCorners * kLpvCorners * kLpvCorners;
// Lpv.h kAoDirections, kAoSteps, kAoCutoff.
const int kLpvAoDirections = 16;
const int kLpvAoSteps = 48;
const float kLpvAoCutoff = 1e-3;

// L1 SH in SphericalHarmonics.h's order (1, y, z, x) evaluated toward d (Lpv.cpp evaluate()).
float lpvShEvaluate(vec4 sh, vec3 d) { return sh.x * kShY00 + kShY1 * (sh.y * d.y + sh.z * d.z + sh.w * d.x); }
// Σ Â_l L_k Y_k(n), Â = {π, 2π/3} (Ramamoorthi & Hanrahan 2001; Lpv.cpp irradianceLinear()).
float lpvIrradianceLinear(vec4 l, vec3 n) {
    return PI * kShY00 * l.x + (2.0 * PI / 3.0) * kShY1 * (l.y * n.y + l.z * n.z + l.w * n.x);
}
float lpvLuminance(vec3 c) { return rec709Luminance(c.r, c.g, c.b); }

// A cascade's fade weight at p: 1 inside, falling to 0 over the fade range (cells) at its faces.
float lpvFade(int c, vec3 p) {
    LpvCascadeRecord cas = lpv.cascades[c];
    vec3 u = (p - cas.minCorner) / cas.cellSize;
    float dist = float(kLpvGrid);
    dist = min(dist, min(min(u.x, u.y), u.z));
    dist = min(dist, min(min(float(kLpvGrid) - u.x, float(kLpvGrid) - u.y), float(kLpvGrid) - u.z));
    if (!(dist >= 0.0)) return 0.0;
    float fade = lpv.fadeRange;
    if (fade <= 0.0) return dist > 0.0 ? 1.0 : 0.0;
    return clamp(dist / fade, 0.0, 1.0);
}

// Trilinear weights over a grid of n texels, texel t at coordinate t (Lpv.cpp trilinear()).
void lpvTrilinear(vec3 u, int n, out ivec3 i0, out vec3 t) {
    vec3 v = clamp(u, vec3(0.0), vec3(float(n - 1)));
    i0 = min(ivec3(v), ivec3(n - 2));
    t = v - vec3(i0);
}

// The radiance SH (intensity / h²) at p, cascades `last` down to 0 blended finest first, each
// taking its fade weight of what the finer ones left. `weight`: their total weight; `cellSize`:
// the cell of the cascade that weighs most (ties: the finer).
void lpvRadiance(vec3 p, int last, out vec4 sh[3], out float weight, out float cellSize) {
    sh[0] = vec4(0.0);
    sh[1] = vec4(0.0);
    sh[2] = vec4(0.0);
    float remaining = 1.0, best = 0.0;
    cellSize = lpv.cascades[0].cellSize;
    for (int c = last; c >= 0; --c) {
        float fade = lpvFade(c, p);
        float w = fade * remaining;
        if (w <= 0.0) continue;
        float h = lpv.cascades[c].cellSize;
        if (w > best) {
            best = w;
            cellSize = h;
        }
        ivec3 i0;
        vec3 t;
        lpvTrilinear((p - lpv.cascades[c].minCorner) / h - 0.5, kLpvGrid, i0, t);
        float toRadiance = 1.0 / (h * h);
        int base = c * 3 * kLpvCells;
        for (int k = 0; k < 8; ++k) {
            ivec3 o = ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
            vec3 wv = mix(vec3(1.0) - t, t, vec3(o));
            float f = wv.x * wv.y * wv.z;
            if (f == 0.0) continue;
            ivec3 cell3 = i0 + o;
            int cell = cell3.x + kLpvGrid * (cell3.y + kLpvGrid * cell3.z);
            float s = w * f * toRadiance;
            sh[0] += s * lpvLight.v[base + cell];
            sh[1] += s * lpvLight.v[base + kLpvCells + cell];
            sh[2] += s * lpvLight.v[base + 2 * kLpvCells + cell];
        }
        remaining *= 1.0 - fade;
    }
    weight = 1.0 - remaining;
}

// The cascades' total weight at p and the dominant cell, without reading the volumes.
float lpvWeight(vec3 p, int last, out float cellSize) {
    float remaining = 1.0, best = 0.0;
    cellSize = lpv.cascades[0].cellSize;
    for (int c = last; c >= 0; --c) {
        float fade = lpvFade(c, p);
        float w = fade * remaining;
        if (w <= 0.0) continue;
        if (w > best) {
            best = w;
            cellSize = lpv.cascades[c].cellSize;
        }
        remaining *= 1.0 - fade;
    }
    return 1.0 - remaining;
}

// The cascades' cells blended by their weights at p, 0 outside all (Lpv.cpp blendedCellSize()).
float lpvBlendedCell(vec3 p, int last) {
    float remaining = 1.0, sum = 0.0;
    for (int c = last; c >= 0; --c) {
        float fade = lpvFade(c, p);
        float w = fade * remaining;
        if (w <= 0.0) continue;
        sum += w * lpv.cascades[c].cellSize;
        remaining *= 1.0 - fade;
    }
    float total = 1.0 - remaining;
    return total > 0.0 ? sum / total : 0.0;
}

// The blended blocking SH at p, on the corner texels (Lpv.cpp geometryAt()).
vec4 lpvGeometryAt(vec3 p, int last) {
    vec4 sum = vec4(0.0);
    float remaining = 1.0;
    for (int c = last; c >= 0; --c) {
        float fade = lpvFade(c, p);
        float w = fade * remaining;
        if (w <= 0.0) continue;
        ivec3 i0;
        vec3 t;
        lpvTrilinear((p - lpv.cascades[c].minCorner) / lpv.cascades[c].cellSize, kLpvCorners, i0, t);
        int base = c * kLpvCornerCount;
        for (int k = 0; k < 8; ++k) {
            ivec3 o = ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
            vec3 wv = mix(vec3(1.0) - t, t, vec3(o));
            ivec3 c3 = i0 + o;
            sum += w * wv.x * wv.y * wv.z * lpvGeometry.v[base + c3.x + kLpvCorners * (c3.y + kLpvCorners * c3.z)];
        }
        remaining *= 1.0 - fade;
    }
    return sum;
}

// ZH3 hallucinated from L1 with the luminance's axis shared by the channels (Roughton et al.,
// "ZH3: Quadratic Zonal Harmonics", I3D 2024, Section 3.4.3; Lpv.cpp irradianceZh3Hallucinated()).
vec3 lpvIrradianceZh3(vec4 l[3], vec3 n) {
    vec3 lum = vec3(rec709Luminance(l[0].w, l[1].w, l[2].w), rec709Luminance(l[0].y, l[1].y, l[2].y),
                    rec709Luminance(l[0].z, l[1].z, l[2].z));
    float len = length(lum);
    vec3 e;
    for (int c = 0; c < 3; ++c) {
        float linear = lpvIrradianceLinear(l[c], n);
        if (!(len > 1e-20)) {
            e[c] = linear;
            continue;
        }
        vec3 axis = lum / len;
        float z2 = 0.0;
        if (l[c].x > 0.0) {
            float ratio = abs(l[c].w * axis.x + l[c].y * axis.y + l[c].z * axis.z) / l[c].x;
            z2 = l[c].x * (0.08 * ratio + 0.6 * ratio * ratio);
        }
        float t = dot(axis, n);
        e[c] = linear + 0.25 * PI * z2 * kShY20 * (3.0 * t * t - 1.0);
    }
    return e;
}

// Irradiance at q on a surface facing n: the light flowing along −n (Lpv.cpp irradianceAt()).
vec3 lpvIrradianceAt(vec3 q, vec3 n, int quality, int last) {
    vec4 l[3];
    float weight, cellSize;
    lpvRadiance(q, last, l, weight, cellSize);
    vec3 e;
    if (quality == 0)
        e = vec3(lpvIrradianceLinear(l[0], -n), lpvIrradianceLinear(l[1], -n), lpvIrradianceLinear(l[2], -n));
    else
        e = lpvIrradianceZh3(l, -n);
    return max(e, vec3(0.0));
}

// Volumes::evaluate at p with unit normal n, toward the eye `toEye`, over cascades `last` to 0.
LpvSample lpvEvaluate(vec3 p, vec3 n, vec3 toEye, int quality, int last) {
    LpvSample s;
    s.irradiance = vec3(0.0);
    s.specular = vec3(0.0);
    float h;
    if (lpvWeight(p, last, h) <= 0.0) return s;
    // Half a cell out along the normal, so a surface does not read its own cell's light.
    float half_ = 0.5 * h;
    vec3 q = p + half_ * n;
    vec3 e = lpvIrradianceAt(q, n, quality, last);
    if (quality >= 1) {
        // Leak dampening by the directional derivative along the normal.
        float front = lpvLuminance(lpvIrradianceAt(q + half_ * n, n, quality, last));
        float back = lpvLuminance(lpvIrradianceAt(q - half_ * n, n, quality, last));
        float centre = lpvLuminance(e);
        if (centre > 0.0) e *= clamp(1.0 + min(0.0, front - back) / centre, 0.0, 1.0);
    }
    if (quality >= 2) {
        // Cone-traced specular: every cell along the mirror direction, each sample dimmed by the
        // geometry passed before it, averaged.
        vec3 r = reflect(-toEye, n);
        vec3 sum = vec3(0.0);
        float transmit = 1.0;
        int samples = max(lpv.coneSamples, 1);
        for (int i = 0; i < samples; ++i) {
            vec3 x = q + float(i + 1) * h * r;
            vec4 l[3];
            float weight, cellSize;
            lpvRadiance(x, last, l, weight, cellSize);
            for (int c = 0; c < 3; ++c) sum[c] += transmit * max(0.0, lpvShEvaluate(l[c], -r));
            transmit *= 1.0 - clamp(lpvShEvaluate(lpvGeometryAt(x, last), r), 0.0, 1.0);
        }
        s.specular = sum / float(samples) * lpv.indirectIntensity;
    }
    s.irradiance = e * lpv.indirectIntensity;
    return s;
}

// Orthonormal basis around a unit normal (Duff et al. 2017; SphereSampling.h basisAround()).
void lpvBasisAround(vec3 n, out vec3 t, out vec3 b) {
    float sign_ = (floatBitsToUint(n.z) & 0x80000000u) != 0u ? -1.0 : 1.0;  // copysign: −0 counts as negative
    float a = -1.0 / (sign_ + n.z);
    float c = n.x * n.y * a;
    t = vec3(1.0 + sign_ * n.x * n.x * a, sign_ * c, -sign_ * n.x);
    b = vec3(c, sign_ + n.y * n.y * a, -n.y);
}

// Cosine-weighted direction i of `count` about n with its basis t, b: a Fibonacci spiral on the
// disk lifted to the hemisphere (SphereSampling.h cosineHemisphere(), azimuth offset 0).
vec3 lpvCosineHemisphere(int i, int count, vec3 n, vec3 t, vec3 b) {
    float r2 = (float(i) + 0.5) / float(count);
    float phi = 2.0 * PI * fract(float(i) * 0.6180339887498949);
    float r = sqrt(r2);
    return normalize(r * cos(phi) * t + sqrt(max(0.0, 1.0 - r2)) * n + r * sin(phi) * b);
}

// The geometry volume's sky visibility at p facing n, 1 open (Lpv.cpp Volumes::ambientOcclusion):
// along each direction, from half a cell above p, a blended cell a step until the volumes end,
// keeping 1 − the blocking of the surfaces facing back toward p. Only view 63 calls it: a CPU
// driver that runs it under a mask for the other views leaves each loop after one pass.
float lpvAmbientOcclusion(vec3 p, vec3 n, int last) {
    float h;
    if (lpvWeight(p, last, h) <= 0.0) return 1.0;
    vec3 q = p + 0.5 * h * n;
    vec3 t, b;
    lpvBasisAround(n, t, b);
    float open = 0.0;
    for (int k = 0; k < kLpvAoDirections; ++k) {
        vec3 w = lpvCosineHemisphere(k, kLpvAoDirections, n, t, b);
        float transmit = 1.0;
        float dist = 0.0;
        for (int j = 0; j < kLpvAoSteps && transmit > kLpvAoCutoff; ++j) {
            float hx = lpvBlendedCell(q + dist * w, last);
            if (hx <= 0.0) break;
            transmit *= 1.0 - clamp(lpvShEvaluate(lpvGeometryAt(q + (dist + 0.5 * hx) * w, last), -w), 0.0, 1.0);
            dist += hx;
        }
        open += transmit;
    }
    return open / float(kLpvAoDirections);
}

// KHR_lights_punctual's range window clamp(1 − (d/range)⁴, 0, 1)/d² and, for a spot, the squared
// smooth cone falloff (Lpv.cpp lightAttenuation()): the irradiance on a surface facing the light
// per unit of emitted colour × intensity.
float localLightAttenuation(LocalLightRecord light, vec3 toSurface, float d) {
    float ratio = d / light.range;
    float window = clamp(1.0 - ratio * ratio * ratio * ratio, 0.0, 1.0);
    float dd = max(d, 0.01);
    float att = window / (dd * dd);
    if (light.spot > 0.5) {
        float t = clamp((dot(light.direction, toSurface) - light.cosOuter) * light.invConeWidth, 0.0, 1.0);
        att *= t * t;
    }
    return att;
}

// The local lights' direct light leaving p toward v: Lambert and GGX as for the sun, unshadowed.
vec3 localLightsDirect(vec3 p, vec3 n, vec3 v, vec3 albedo, float roughness) {
    vec3 sum = vec3(0.0);
    for (int i = 0; i < lpv.lightCount; ++i) {
        LocalLightRecord light = localLights.l[i];
        vec3 toLight = light.position - p;
        float d = length(toLight);
        if (!(d < light.range) || d <= 0.0) continue;
        vec3 l = toLight / d;
        float att = localLightAttenuation(light, -l, d);
        if (att <= 0.0) continue;
        vec3 e = light.emitted * att;
        sum += albedo / PI * e * max(dot(n, l), 0.0) + ggxSpecular(n, v, l, roughness) * e;
    }
    return sum;
}

#endif  // TLX_LPV
#endif
