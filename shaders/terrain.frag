#version 450
#extension GL_GOOGLE_include_directive : require
// Terrain shading (LIGHTING.md): Lambert + GGX sun, sky irradiance from SH, baked probe
// irradiance blended over it, ACES tonemap, sRGB encoding; and the debug views.
#include "frame.glsl"

layout(location = 0) in vec3 worldPos;
layout(location = 1) in vec3 worldNormal;
// rgb irradiance, a blend weight; in views 54 and 56 the diagnostics instead: x share of moved
// probes in the blend (-1 where no probe lights the point), y interpolation error × known,
// z known (1 = measured), w 1 = inside a volume with no probe to light it.
layout(location = 2) in vec4 probeIrradianceWeight;
layout(location = 0) out vec4 outColor;

#include "probes.glsl"

// ACES filmic fit (Narkowicz 2015, "ACES Filmic Tone Mapping Curve").
vec3 aces(vec3 x) {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}
vec3 srgb(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}
vec3 display(vec3 linear) {
    return frame.params.w == 1 ? linear : srgb(aces(linear * frame.exposure.x));
}

// Heat ramp for view 56: 0 dark blue, 2.5 % cyan, 5 % green, 7.5 % yellow, 10 % and above red.
vec3 heat(float e) {
    // Piecewise linear over the stops, without an indexed array (which a CPU driver may build for
    // every fragment of every view).
    float t = clamp(e / 0.10, 0.0, 1.0) * 4.0;
    if (t < 1.0) return mix(vec3(0.05, 0.10, 0.55), vec3(0.0, 0.65, 0.90), t);
    if (t < 2.0) return mix(vec3(0.0, 0.65, 0.90), vec3(0.15, 0.80, 0.20), t - 1.0);
    if (t < 3.0) return mix(vec3(0.15, 0.80, 0.20), vec3(1.0, 0.85, 0.10), t - 2.0);
    return mix(vec3(1.0, 0.85, 0.10), vec3(0.90, 0.10, 0.05), t - 3.0);
}

void main() {
    vec3 n = normalize(worldNormal);
    vec3 l = normalize(frame.sunDirection.xyz);
    vec3 v = normalize(frame.cameraPos.xyz - worldPos);
    vec3 albedo = frame.albedo.rgb;
    float ndotl = max(dot(n, l), 0.0);

    int view = frame.params.x;
    vec3 sky = skyIrradiance(n);
    float weight = probeIrradianceWeight.a;
    vec3 probe = probeIrradianceWeight.rgb;
    // Disabled or absent probes leave the sky term exactly as it is.
    vec3 ambient = weight > 0.0 ? mix(sky, probe, weight) : sky;

    // GGX (Walter et al. 2007) with Schlick Fresnel and the Smith-Schlick visibility term.
    float rough = frame.exposure.y, a = rough * rough;
    vec3 hv = normalize(l + v);
    float ndoth = max(dot(n, hv), 0.0), ndotv = max(dot(n, v), 1e-4);
    float d = a * a / (PI * pow(ndoth * ndoth * (a * a - 1.0) + 1.0, 2.0));
    float k = a * 0.5;
    float g = ndotl / (ndotl * (1.0 - k) + k) * ndotv / (ndotv * (1.0 - k) + k);
    float fres = 0.04 + 0.96 * pow(1.0 - max(dot(hv, v), 0.0), 5.0);
    vec3 spec = vec3(d * g * fres / max(4.0 * ndotl * ndotv, 1e-4)) * ndotl;

    vec3 sun = frame.sunIlluminance.rgb;
    vec3 linear = albedo / PI * (sun * ndotl + ambient) + spec * sun;

    vec3 c;
    if (view == 1) c = frame.params.w == 1 ? albedo : srgb(albedo);
    else if (view == 2) c = n * 0.5 + 0.5;
    else if (view == 30) c = vec3(ndotl);
    else if (view == 32) c = frame.params.w == 1 ? linear : clamp(linear, 0.0, 1.0);
    else if (view == 50) c = display(probe * weight / PI);
    else if (view == 51) c = vec3(weight);
    else if (view == 54) {
        // Probe validity: grey where probes at their placement light the ground, cyan as moved
        // probes take part, red inside a volume where no valid probe is left, dark outside.
        vec4 d = probeIrradianceWeight;
        float relief = 0.55 + 0.45 * max(n.y, 0.0);
        vec3 base = d.w > 0.5  ? vec3(0.85, 0.12, 0.10)
                  : d.x > -0.5 ? mix(vec3(0.72), vec3(0.10, 0.80, 1.0), clamp(d.x, 0.0, 1.0))
                               : vec3(0.18);
        c = base * relief;
    } else if (view == 56) {
        // Interpolation error: EXR holds the error in red and 1 in green where measured.
        float known = probeIrradianceWeight.z;
        float error = known > 0.0 ? probeIrradianceWeight.y / known : 0.0;
        if (frame.params.w == 1) c = vec3(known > 0.5 ? error : 0.0, known > 0.5 ? 1.0 : 0.0, 0.0);
        else c = (known > 0.5 ? heat(error) : vec3(0.25)) * (0.75 + 0.25 * max(n.y, 0.0));
    }
    else c = display(linear);
    outColor = vec4(c, 1.0);
}
