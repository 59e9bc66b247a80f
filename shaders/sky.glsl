// Sky irradiance from the sky's SH (include after blocks/sun_sky.h and sh.glsl).
#ifndef TLX_SKY_GLSL
#define TLX_SKY_GLSL

vec3 skyIrradiance(vec3 n) {
    vec3 c[9];
    for (int k = 0; k < 9; ++k) c[k] = sunSky.skySh[k].rgb;
    return max(shIrradiance(c, n, false), vec3(0.0));
}

#endif
