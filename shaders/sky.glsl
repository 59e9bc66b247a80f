// The sky's irradiance and radiance from its SH (include after blocks/sun_sky.h and sh.glsl).
#ifndef TLX_SKY_GLSL
#define TLX_SKY_GLSL

vec3 skyIrradiance(vec3 n) {
    vec3 c[9];
    for (int k = 0; k < 9; ++k) c[k] = sunSky.skySh[k].rgb;
    return max(shIrradiance(c, n, false), vec3(0.0));
}

// The sky's radiance toward r (below the horizon, the horizon's), as the sky pass draws it: the
// SH radiance itself, Σ L_k Y_k(r) (shIrradiance with the factors left out).
vec3 skyRadiance(vec3 r) {
    vec3 up = normalize(vec3(r.x, max(r.y, 0.0), r.z) + vec3(0.0, 1e-4, 0.0));
    vec3 c[9];
    for (int k = 0; k < 9; ++k) c[k] = sunSky.skySh[k].rgb;
    return max(shIrradiance(c, up, true), vec3(0.0));
}

#endif
