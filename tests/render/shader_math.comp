#version 450
// Evaluates the rules C++ and GLSL share (shaders/ShaderMath.h) at the test's inputs, with the
// shaders' own headers, so test_shader_math can hold the C++ evaluation to the device's.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

#include "display_math.glsl"
#include "fog_math.glsl"
#include "sh_basis.glsl"
#include "sky_math.glsl"
#include "shadow_math.glsl"

// Per sample two vec4: a = (scene-linear light, a value in [0, 1], height above the fog's base
// (m), Henyey–Greenstein g); b = (unit direction xyz, distance (m)).
layout(std430, set = 0, binding = 0) readonly buffer Inputs { vec4 inputs[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Outputs { float outputs[]; };
layout(push_constant) uniform Push { ivec4 count; } push;

const int kOutputs = 22;

void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= push.count.x) return;
    vec4 a = inputs[2 * i], b = inputs[2 * i + 1];
    int o = i * kOutputs;
    outputs[o + 0] = acesFit(a.x);
    outputs[o + 1] = srgbEncode(a.y);
    outputs[o + 2] = srgbDecode(a.y);
    outputs[o + 3] = acesFitInverse(a.y);
    for (int k = 0; k < 9; ++k) outputs[o + 4 + k] = shBasis(k, b.x, b.y, b.z);
    outputs[o + 13] = fogOpticalDepth(0.002, 0.001, a.z, b.y, b.w);
    outputs[o + 14] = henyeyGreenstein(a.w, b.y);
    outputs[o + 15] = srgbEncode(acesFit(a.x));
    outputs[o + 16] = fogSkyOpticalDepth(0.002, 0.001, a.z, b.y, b.w);
    outputs[o + 17] = equirectU(b.x, b.z, a.y);
    outputs[o + 18] = equirectV(b.y);
    outputs[o + 19] = shadowShortestDrawn(0.01 * b.w, 2.0 * a.y);
    outputs[o + 20] = shadowTakesHorizon(0.01 * b.w, 2.0 * a.y, 60.0) ? 1.0 : 0.0;
    outputs[o + 21] = rec709Luminance(a.x, a.y, abs(b.x));
}
