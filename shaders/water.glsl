// Gerstner waves over the water plane (docs/lighting.md, "Water"); the C++ twin is
// renderer/water/Water.cpp, held to this one by tests/render/test_shader_math.cpp. Include after blocks/water.h, blocks/surface.h and sh.glsl (PI).
#ifndef TLX_WATER_GLSL
#define TLX_WATER_GLSL

layout(set = TLX_SET_SUBSYSTEM, binding = TLX_WATER_FIELD_BINDING) uniform sampler2D waterField;

const float kGravity = 9.81;
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
float shoreFade(float distance) {
    float d = water.shoreFade;
    return d > 0.0 ? smoothstep(0.0, d, distance) : 1.0;
}

// ω of wave i at water depth h: √(g·k·tanh(k·h)) when depth-aware (Airy), else deep water √(g·k).
float waveOmega(int i, float depth) {
    float k = water.waves[i].k;
    return water.depthAware > 0.5 ? sqrt(kGravity * k * tanh(k * max(depth, 0.0))) : water.waves[i].omegaDeep;
}

// Displacement of the rest point xz and the surface's unit normal there (Tessendorf 2001, eq.
// 41 with Q = 1; the normal is the cross product of the surface's exact tangents along z and
// x, which Finch 2004, GPU Gems ch. 1, eq. 12 approximates to first order). Waves
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
        float theta = k * dot(d, xz) - waveOmega(i, depth) * water.time + water.waves[i].phase;
        float c = cos(theta), s = sin(theta);
        displacement += vec3(d.x * a * c, a * s, d.y * a * c);
        float ka = k * a;
        tx += vec3(-d.x * d.x * ka * s, d.x * ka * c, -d.x * d.y * ka * s);
        tz += vec3(-d.x * d.y * ka * s, d.y * ka * c, -d.y * d.y * ka * s);
    }
    normal = normalize(cross(tz, tx));
}

#endif
