#version 450
#extension GL_GOOGLE_include_directive : require
// The water surface (docs/lighting.md, "Water"): Schlick-Fresnel mix of the reflection (planar
// or the sky's) and what lies below, the bed seen through the absorbing water plus the light the
// water body scatters; the sun's highlight on the waves, shadowed by the cascades; fog as on the
// terrain. Built four times like the terrain: with TLX_SHADOWS the sun is shadowed by the
// cascades; with TLX_REFLECTIONS the sky's reflection gives way to the nearest reflection probe's
// where the probes cover the water.
#include "blocks/glsl.h"
#include "blocks/camera.h"
#include "blocks/surface.h"
#include "blocks/sun_sky.h"
#include "blocks/atmosphere.h"
#include "blocks/water.h"
#include "sh.glsl"
#include "sky.glsl"
#include "brdf.glsl"
#include "tonemap.glsl"
// The water lies above the ground the horizon map describes: it keeps the maps.
#define TLX_SHADOW_MAPS_ONLY
#include "shadows.glsl"
#include "fog.glsl"
#include "reflections.glsl"
#include "water.glsl"

#define TLX_VIEW(NAME, NUMBER) const int kView##NAME = NUMBER;
#include "debug_views.def"
#undef TLX_VIEW

layout(set = TLX_SET_SUBSYSTEM, binding = TLX_WATER_REFLECTION_BINDING) uniform sampler2D reflectionMap;
layout(set = TLX_SET_SUBSYSTEM, binding = TLX_WATER_SCENE_BINDING) uniform sampler2D sceneBelow;

layout(location = 0) in vec3 restPos;
layout(location = 1) in vec3 worldPos;
layout(location = 0) out vec4 outColor;

const float kWaterIor = 1.33;

// The frame under the water back to scene-linear light: the target holds the display encoding
// (sRGB of the ACES fit of the exposed light) unless the output is linear: display_math.glsl's
// inverses undo it.
vec3 storedToLinear(vec3 stored) {
    if (linearOutput() || camera.debugView == kViewLinear) return stored;
    vec3 x = vec3(acesFitInverse(srgbDecode(stored.r)), acesFitInverse(srgbDecode(stored.g)),
                  acesFitInverse(srgbDecode(stored.b)));
    return x / max(surface.exposure, 1e-6);
}

void main() {
    // Map reads and derivatives first, in uniform control flow.
    vec2 field = waterFieldAt(restPos.xz);
    float depth = max(field.x, 0.0);  // metres of water over the bed
    float pixelMetres = length(fwidth(worldPos));
    vec3 face = faceNormal(worldPos, vec3(0.0, 1.0, 0.0));
    vec3 displacement, n;
    gerstner(restPos.xz, depth, shoreFade(field.y), pixelMetres, displacement, n);
    vec2 screen = gl_FragCoord.xy * camera.invViewportSize;
    float distortion = water.distortion;
    vec3 planar = texture(reflectionMap, screen + n.xz * distortion).rgb;
    vec3 bedStored = texture(sceneBelow, clamp(screen + n.xz * (0.5 * distortion), vec2(0.0), vec2(1.0))).rgb;

    int view = camera.debugView;
    if (view == kViewWaterMask) {
        outColor = vec4(linearOutput() ? vec3(1.0, 1.0, 0.0) : vec3(0.10, 0.45, 1.0), 1.0);
        return;
    }
    if (view == kViewShoreDistance) {
        // EXR: metres in red; PNG: the fade distance as the ramp's span (heat's 10 % = full).
        float span = max(water.shoreFade, 1.0);
        outColor = vec4(linearOutput() ? vec3(field.y, 1.0, 0.0) : heat(0.1 * clamp(field.y / span, 0.0, 1.0)), 1.0);
        return;
    }
    if (view == kViewWaterNormal) {
        outColor = vec4(n * 0.5 + 0.5, 1.0);
        return;
    }

    vec3 v = normalize(camera.position - worldPos);
    float ndotv = max(dot(n, v), 1e-3);
    float fresnel = kWaterF0 + (1.0 - kWaterF0) * pow(1.0 - ndotv, 5.0);
    vec3 reflected = planar;
    if (water.planarReflection <= 0.5) {
        // The sky's reflection, or where reflection probes cover the water the nearest probe's
        // (one probe: the water is a mirror, and a blend of probes would double its images).
        vec3 r = reflect(-v, n);
        reflected = skyRadiance(r);
        float w = reflectionWeight(worldPos);
        if (w > 0.0) reflected = mix(reflected, nearestReflectionProbeRadiance(worldPos, r, water.roughness), w);
    }

    vec3 l = normalize(sunSky.sunDirection);
    float shadowed = sunShadow(worldPos, n, face);
    vec3 sun = sunSky.sunIlluminance * shadowed;
    vec3 highlight = ggxSpecularF0(n, v, l, water.roughness, kWaterF0) * sun;

    // Below the surface: the path to the bed along the refracted view ray, and the sun's path
    // down to it along its refracted direction; both absorb (Beer–Lambert). The bed in the frame
    // was lit as if in air, so both paths darken it; the water body scatters the light that
    // enters it over the view path (single scattering, the scatter albedo times the irradiance
    // through the surface over π).
    vec3 t = refract(-v, n, 1.0 / kWaterIor);
    float viewPath = depth / max(-t.y, 0.2);
    vec3 ls = refract(-l, vec3(0.0, 1.0, 0.0), 1.0 / kWaterIor);
    float sunPath = depth / max(-ls.y, 0.2);
    vec3 viewT = exp(-water.absorption * viewPath);
    vec3 bed = storedToLinear(bedStored) * viewT * exp(-water.absorption * sunPath);
    vec3 irradiance = sun * max(l.y, 0.0) + skyIrradiance(vec3(0.0, 1.0, 0.0));
    vec3 body = water.scatter * irradiance / PI * (1.0 - viewT);
    vec3 radiance = fresnel * reflected + (1.0 - fresnel) * (bed + body) + highlight;

    vec3 toPoint = worldPos - camera.position;
    float distance = length(toPoint);
    radiance = applyFog(radiance, toPoint / max(distance, 1e-6), distance);
    if (view == kViewLinear) {
        outColor = vec4(linearOutput() ? radiance : clamp(radiance, 0.0, 1.0), 1.0);
        return;
    }
    outColor = vec4(display(radiance), 1.0);
}
