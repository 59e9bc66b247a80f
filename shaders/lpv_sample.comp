#version 450
#extension GL_GOOGLE_include_directive : require
// Volumes::evaluate and Volumes::ambientOcclusion on the GPU at given points
// (TerrainRenderer::sampleLpv): the terrain pass's own LPV code, read back so the tests can hold
// it against the CPU's at the same points.
layout(local_size_x = 64) in;
#define TLX_LPV
#include "blocks/glsl.h"
#include "blocks/lpv.h"
#include "sh.glsl"
#include "brdf.glsl"
#include "lpv.glsl"

// Per query: position, normal, toward the eye (xyz each, w unused).
layout(set = TLX_SET_SUBSYSTEM, binding = 4, std430) readonly buffer Queries { vec4 v[]; } queries;
// Per query: (irradiance, ambient occlusion), (specular, 0).
layout(set = TLX_SET_SUBSYSTEM, binding = 5, std430) writeonly buffer Results { vec4 v[]; } results;
layout(push_constant) uniform Push { ivec4 countLast; } push;  // x queries, y last cascade

void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= push.countLast.x) return;
    vec3 p = queries.v[3 * i].xyz, n = queries.v[3 * i + 1].xyz, toEye = queries.v[3 * i + 2].xyz;
    LpvSample s = lpvEvaluate(p, n, toEye, lpv.quality, push.countLast.y);
    results.v[2 * i] = vec4(s.irradiance, lpvAmbientOcclusion(p, n, push.countLast.y));
    results.v[2 * i + 1] = vec4(s.specular, 0.0);
}
