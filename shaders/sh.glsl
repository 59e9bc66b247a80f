// Spherical-harmonics irradiance (docs/formats.md basis).
#ifndef TLX_SH_GLSL
#define TLX_SH_GLSL

const float PI = 3.14159265358979;

// Irradiance of SH radiance coefficients for normal n: Σ Â_l L_k Y_k(n) (Ramamoorthi and
// Hanrahan 2001). `convolved` = the coefficients already hold Â_l L_k.
vec3 shIrradiance(vec3 c[9], vec3 n, bool convolved) {
    float y[9];
    y[0] = 0.282095;
    y[1] = 0.488603 * n.y;
    y[2] = 0.488603 * n.z;
    y[3] = 0.488603 * n.x;
    y[4] = 1.092548 * n.x * n.y;
    y[5] = 1.092548 * n.y * n.z;
    y[6] = 0.315392 * (3.0 * n.z * n.z - 1.0);
    y[7] = 1.092548 * n.x * n.z;
    y[8] = 0.546274 * (n.x * n.x - n.y * n.y);
    const float a0 = convolved ? 1.0 : PI, a1 = convolved ? 1.0 : 2.0 * PI / 3.0,
                a2 = convolved ? 1.0 : PI / 4.0;
    vec3 e = a0 * c[0] * y[0];
    for (int k = 1; k < 4; ++k) e += a1 * c[k] * y[k];
    for (int k = 4; k < 9; ++k) e += a2 * c[k] * y[k];
    return e;
}

#endif
