// The real spherical-harmonics basis of bands 0 to 2 (docs/formats.md, "SH convention"), in the
// common subset of GLSL and C++ (shaders/ShaderMath.h includes it for C++): the constants and
// Y_k(n) written once for the shaders, the LPV and the tests. The CPU bake keeps the same closed
// forms in double precision (bake/SphericalHarmonics.cpp); a test holds the two equal in float.
#ifndef TLX_SH_BASIS_GLSL
#define TLX_SH_BASIS_GLSL
#ifndef TLX_SHARED
#define TLX_SHARED
#endif

const float kShY00 = 0.28209479177387814f;  // 1/(2√π)
const float kShY1 = 0.48860251190291992f;   // √(3/(4π)): y, z, x
const float kShY2 = 1.0925484305920792f;    // ½√(15/π): xy, yz, xz
const float kShY20 = 0.31539156525252005f;  // ¼√(5/π): 3z² − 1
const float kShY22 = 0.54627421529603959f;  // ¼√(15/π): x² − y²

// Y_k at the unit direction (x, y, z), k in [0, 9), in the order of docs/formats.md.
TLX_SHARED float shBasis(int k, float x, float y, float z) {
    if (k == 0) return kShY00;
    if (k == 1) return kShY1 * y;
    if (k == 2) return kShY1 * z;
    if (k == 3) return kShY1 * x;
    if (k == 4) return kShY2 * x * y;
    if (k == 5) return kShY2 * y * z;
    if (k == 6) return kShY20 * (3.0f * z * z - 1.0f);
    if (k == 7) return kShY2 * x * z;
    return kShY22 * (x * x - y * y);
}

#endif
