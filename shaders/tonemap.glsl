// Display encoding (include after blocks/camera.h and blocks/surface.h).
#ifndef TLX_TONEMAP_GLSL
#define TLX_TONEMAP_GLSL

// ACES filmic fit (Narkowicz 2015, "ACES Filmic Tone Mapping Curve").
vec3 aces(vec3 x) {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}
vec3 srgb(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}
bool linearOutput() { return camera.view.y == 1; }
// Scene-linear light as the output wants it: as is for EXR, exposed, tonemapped and sRGB for PNG.
vec3 display(vec3 linear) {
    return linearOutput() ? linear : srgb(aces(linear * surface.material.y));
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
