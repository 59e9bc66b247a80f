// Gerstner waves and their dispersion, written once in the common subset of GLSL and C++: the
// water shaders evaluate them in float (water.glsl), renderer/water/Water.cpp in double
// (through shaders/ShaderMath.h, terralux::glsl::dbl); docs/lighting.md, "Water".
// The includer may set TLX_REAL, TLX_RVEC2, TLX_RVEC3 and TLX_INOUT(T) (C++: double, glm's double
// vectors, a reference); GLSL takes float, vec2, vec3 and inout.
#ifndef TLX_WATER_MATH_GLSL
#define TLX_WATER_MATH_GLSL
#ifndef TLX_SHARED
#define TLX_SHARED
#endif
#ifndef TLX_REAL
#define TLX_REAL float
#define TLX_RVEC2 vec2
#define TLX_RVEC3 vec3
#define TLX_INOUT(T) inout T
#endif

#define TLX_GRAVITY 9.81  // m/s²

// ω at water depth h: the dispersion relation of linear (Airy) waves over a bed at depth h,
// ω² = g·k·tanh(k·h), which is g·k in deep water (k·h → ∞) and g·h·k² in shallow water
// (Tessendorf, "Simulating Ocean Water", SIGGRAPH 2001 course notes). Dry ground (h <= 0) holds a
// wave still.
TLX_SHARED TLX_REAL waveOmegaAtDepth(TLX_REAL k, TLX_REAL depth) {
    return sqrt(TLX_REAL(TLX_GRAVITY) * k * tanh(k * max(depth, TLX_REAL(0))));
}

// θ = k·(D·(x, z)) − ω·t + φ for a wave of unit direction D at rest point xz.
TLX_SHARED TLX_REAL gerstnerPhase(TLX_RVEC2 d, TLX_REAL k, TLX_RVEC2 xz, TLX_REAL omega, TLX_REAL t, TLX_REAL phase) {
    return k * dot(d, xz) - omega * t + phase;
}

// Adds one wave of amplitude a at phase θ (Finch, "Effective Water Simulation from Physical
// Models", GPU Gems 2004, ch. 1, with Q = 1/(k·A); Tessendorf 2001, eq. 41, shifted a quarter
// period): P = (x + Σ D_x·A·cos θ, Σ A·sin θ, z + Σ D_z·A·cos θ), a point moving on a circle of
// radius A. Also adds the wave to the surface's exact tangents ∂P/∂x and ∂P/∂z.
TLX_SHARED void gerstnerAdd(TLX_RVEC2 d, TLX_REAL k, TLX_REAL a, TLX_REAL theta, TLX_INOUT(TLX_RVEC3) displacement,
                            TLX_INOUT(TLX_RVEC3) tx, TLX_INOUT(TLX_RVEC3) tz) {
    TLX_REAL c = cos(theta);
    TLX_REAL s = sin(theta);
    displacement += TLX_RVEC3(d.x * a * c, a * s, d.y * a * c);
    TLX_REAL ka = k * a;
    tx += TLX_RVEC3(-d.x * d.x * ka * s, d.x * ka * c, -d.x * d.y * ka * s);
    tz += TLX_RVEC3(-d.x * d.y * ka * s, d.y * ka * c, -d.y * d.y * ka * s);
}

// The unit normal from the summed tangents (start them at (1, 0, 0) and (0, 0, 1)): ∂P/∂z × ∂P/∂x.
TLX_SHARED TLX_RVEC3 gerstnerNormal(TLX_RVEC3 tx, TLX_RVEC3 tz) { return normalize(cross(tz, tx)); }

// Amplitude scale by distance to shore: smoothstep(0, fadeDistance, distance); 1 without a fade.
TLX_SHARED TLX_REAL waveShoreFade(TLX_REAL distance, TLX_REAL fadeDistance) {
    if (!(fadeDistance > TLX_REAL(0))) return TLX_REAL(1);
    TLX_REAL x = clamp(distance / fadeDistance, TLX_REAL(0), TLX_REAL(1));
    return x * x * (TLX_REAL(3) - TLX_REAL(2) * x);
}

#endif
