// Height-fog optics in closed form, written in the common subset of GLSL and C++ so the shaders
// and the CPU (tests, exporters) evaluate the same expressions (docs/lighting.md, "Height fog").
// C++ includes it through shaders/ShaderMath.h.
#ifndef TLX_FOG_MATH_GLSL
#define TLX_FOG_MATH_GLSL
#ifndef TLX_SHARED
#define TLX_SHARED
#endif

// Optical depth of σ(h) = density · exp(−falloff · (h − base)) along a ray that starts at height
// `startAboveBase` above the base, rises `dirY` metres per metre and runs `distance` metres:
// ∫₀ᴰ σ dt = σ(h₀) · D · g(x), with x = falloff · dirY · D and g(x) = (1 − e^−x) / x. Near x = 0
// (a horizontal ray, or no falloff) g takes its series 1 − x/2 + x²/6 − x³/24: no division by zero.
TLX_SHARED float fogOpticalDepth(float density, float falloff, float startAboveBase, float dirY, float distance) {
    float x = max(falloff * dirY * distance, -80.0f);  // e^80 is within float range
    float series = 1.0f - x * (0.5f - x * (0.16666667f - x * 0.041666667f));
    float g = series;
    if (abs(x) >= 1.0e-2f) g = (1.0f - exp(-x)) / x;
    return density * exp(max(-falloff * startAboveBase, -80.0f)) * distance * g;
}

// Optical depth toward the sky: a rising ray in fog that thins with height leaves it for good, so
// its depth is the whole ray's, the limit of fogOpticalDepth as D → ∞: σ(h₀) / (falloff · dirY).
// It grows without bound toward the horizon, as the depth to level ground below the horizon does,
// so the sky meets the fogged ground there without a seam. Uniform fog (no falloff) has no top,
// and a ray that does not rise meets the far plane: `farDistance` for those.
TLX_SHARED float fogSkyOpticalDepth(float density, float falloff, float startAboveBase, float dirY, float farDistance) {
    float rise = falloff * dirY;
    float whole = density * exp(max(-falloff * startAboveBase, -80.0f)) / max(rise, 1.0e-30f);
    float toFar = fogOpticalDepth(density, falloff, startAboveBase, dirY, farDistance);
    return rise > 0.0f ? whole : toFar;
}

// Henyey–Greenstein phase function (Henyey & Greenstein 1941), normalised over the sphere;
// cosTheta between the direction light travels and the direction it scatters into.
TLX_SHARED float henyeyGreenstein(float g, float cosTheta) {
    float d = 1.0f + g * g - 2.0f * g * cosTheta;
    return (1.0f - g * g) / (4.0f * 3.14159265f * d * sqrt(max(d, 1.0e-6f)));
}

#endif
