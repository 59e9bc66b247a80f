#version 450
// The water shaders' Gerstner waves (water.glsl's gerstner) at the test's rest points, with the
// water block as the renderer packs it, so test_shader_math can hold water::gerstner to them.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64) in;

#include "blocks/glsl.h"
#include "blocks/surface.h"
#include "blocks/water.h"
#include "sh.glsl"
#include "water.glsl"

// Per point: xy rest (x, z), z depth of the bed below the level (m), w the shore fade.
layout(std430, set = TLX_SET_SUBSYSTEM, binding = 5) readonly buffer Points { vec4 points[]; };
// Per point: displacement and normal (two vec4).
layout(std430, set = TLX_SET_SUBSYSTEM, binding = 6) writeonly buffer Surface { vec4 results[]; };
layout(push_constant) uniform Push { ivec4 count; } push;

void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= push.count.x) return;
    vec4 p = points[i];
    vec3 displacement, normal;
    // No wave is shorter than the footprint of 0 m: every wave counts, as on the CPU.
    gerstner(p.xy, p.z, p.w, 0.0, displacement, normal);
    results[2 * i] = vec4(displacement, 0.0);
    results[2 * i + 1] = vec4(normal, 0.0);
}
