// Gerstner waves over the water plane (docs/lighting.md, "Water"), from the water block: the
// terms are water_math.glsl's, which renderer/water/Water.cpp evaluates in double;
// tests/render/test_shader_math.cpp holds the two together. Include after blocks/water.h,
// blocks/surface.h and sh.glsl (PI).
#ifndef TLX_WATER_GLSL
#define TLX_WATER_GLSL

layout(set = TLX_SET_SUBSYSTEM, binding = TLX_WATER_FIELD_BINDING) uniform sampler2D waterField;

#include "water_math.glsl"

const float kWaterF0 = 0.02;  // ((1.33 − 1) / (1.33 + 1))²

// Depth of the bed below the level and distance to shore at a rest position (the field spans
// the footprint corner to corner, like the surface maps; off the footprint it holds the
// border's values).
vec2 waterFieldAt(vec2 xz) {
    vec2 t = clamp((xz - surface.footprintMin) * surface.invFootprintSpan, 0.0, 1.0);
    vec2 size = water.fieldSize;
    return textureLod(waterField, (t * (size - 1.0) + 0.5) / size, 0.0).xy;
}

// Amplitude scale near the shore: smoothstep over the fade distance.
float shoreFade(float distance) { return waveShoreFade(distance, water.shoreFade); }

// ω of wave i at water depth h: depth-aware (Airy), else deep water √(g·k).
float waveOmega(int i, float depth) {
    return water.depthAware > 0.5 ? waveOmegaAtDepth(water.waves[i].k, depth) : water.waves[i].omegaDeep;
}

// Displacement of the rest point xz and the surface's unit normal there (water_math.glsl). Waves
// shorter than `shortest` metres (under the pixel, or the mesh) are left out of the
// displacement and faded out of the normal: what they would add is aliasing. The fragment
// shader passes its pixel's footprint (length(fwidth), already about twice a pixel at an angle),
// the mesh twice its spacing.
void gerstner(vec2 xz, float depth, float fade, float shortest, out vec3 displacement, out vec3 normal) {
    displacement = vec3(0.0);
    vec3 tx = vec3(1.0, 0.0, 0.0), tz = vec3(0.0, 0.0, 1.0);  // ∂P/∂x, ∂P/∂z
    int count = int(water.waveCount);
    for (int i = 0; i < TLX_MAX_WAVES; ++i) {
        if (i >= count) break;
        vec2 d = water.waves[i].direction;
        float k = water.waves[i].k;
        float wavelength = 2.0 * PI / k;
        // None at `shortest`, full from twice it: a wave sampled fewer than four times a
        // wavelength would alias into moiré.
        float keep = clamp(wavelength / max(shortest, 1e-6) - 1.0, 0.0, 1.0);
        float a = water.waves[i].amplitude * fade * keep;
        float theta = gerstnerPhase(d, k, xz, waveOmega(i, depth), water.time, water.waves[i].phase);
        gerstnerAdd(d, k, a, theta, displacement, tx, tz);
    }
    normal = gerstnerNormal(tx, tz);
}

#endif
