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

#endif
