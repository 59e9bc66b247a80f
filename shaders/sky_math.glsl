// The equirectangular sky's mapping (renderer/bake/Sky.h), in the common subset of GLSL and C++
// (shaders/ShaderMath.h includes it for C++): the bake samples its sky image and the sky pass
// draws the same image through these two functions.
#ifndef TLX_SKY_MATH_GLSL
#define TLX_SKY_MATH_GLSL
#ifndef TLX_SHARED
#define TLX_SHARED
#endif

// u of the unit direction (x, y, z): 0.5 + φ / 2π − rotation wrapped to [0, 1), φ = atan2(x, −z)
// the azimuth clockwise from north (−Z) toward east (+X); `rotation` in turns. At rotation 0 the
// image's centre column faces north.
TLX_SHARED float equirectU(float x, float z, float rotation) {
    float u = 0.5f + atan(x, -z) / (2.0f * 3.14159265358979f) - rotation;
    return u - floor(u);
}

// v of a unit direction with height y: acos(y) / π, 0 at the zenith, 1 at the nadir.
TLX_SHARED float equirectV(float y) {
    return acos(clamp(y, -1.0f, 1.0f)) / 3.14159265358979f;
}

#endif
