// Display encoding (include after blocks/camera.h and blocks/surface.h).
#ifndef TLX_TONEMAP_GLSL
#define TLX_TONEMAP_GLSL

#include "display_math.glsl"

vec3 aces(vec3 x) { return vec3(acesFit(x.r), acesFit(x.g), acesFit(x.b)); }
vec3 srgb(vec3 c) { return vec3(srgbEncode(c.r), srgbEncode(c.g), srgbEncode(c.b)); }
bool linearOutput() { return camera.linearOutput == 1; }
// Scene-linear light as the output wants it: as is for EXR, exposed, tonemapped and sRGB for PNG.
vec3 display(vec3 linear) {
    return linearOutput() ? linear : srgb(aces(linear * surface.exposure));
}

// Heat ramp: 0 dark blue, 2.5 % cyan, 5 % green, 7.5 % yellow, 10 % and above red. Piecewise
// linear over the stops, without an indexed array (which a CPU driver may build for every
// fragment).
vec3 heat(float e) {
    float t = clamp(e / 0.10, 0.0, 1.0) * 4.0;
    if (t < 1.0) return mix(vec3(0.05, 0.10, 0.55), vec3(0.0, 0.65, 0.90), t);
    if (t < 2.0) return mix(vec3(0.0, 0.65, 0.90), vec3(0.15, 0.80, 0.20), t - 1.0);
    if (t < 3.0) return mix(vec3(0.15, 0.80, 0.20), vec3(1.0, 0.85, 0.10), t - 2.0);
    return mix(vec3(1.0, 0.85, 0.10), vec3(0.90, 0.10, 0.05), t - 3.0);
}

#endif
