// Spherical-harmonics irradiance (docs/formats.md basis).
#ifndef TLX_SH_GLSL
#define TLX_SH_GLSL

#include "sh_basis.glsl"

const float PI = 3.14159265358979;

// Irradiance of SH radiance coefficients for normal n: Σ Â_l L_k Y_k(n) (Ramamoorthi and
// Hanrahan 2001). `convolved` = the coefficients already hold Â_l L_k.
vec3 shIrradiance(vec3 c[9], vec3 n, bool convolved) {
    float y[9];
    for (int k = 0; k < 9; ++k) y[k] = shBasis(k, n.x, n.y, n.z);
    const float a0 = convolved ? 1.0 : PI, a1 = convolved ? 1.0 : 2.0 * PI / 3.0,
                a2 = convolved ? 1.0 : PI / 4.0;
    vec3 e = a0 * c[0] * y[0];
    for (int k = 1; k < 4; ++k) e += a1 * c[k] * y[k];
    for (int k = 4; k < 9; ++k) e += a2 * c[k] * y[k];
    return e;
}

#endif
