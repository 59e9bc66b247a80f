#version 450
#extension GL_GOOGLE_include_directive : require
// Probe irradiance and blend weight for every terrain vertex, once per change of probes: the
// draw then reads it as a vertex attribute, so probe lighting costs a frame almost nothing.
layout(local_size_x = 64) in;
#include "frame.glsl"
#include "probes.glsl"

layout(set = 0, binding = 4, std430) readonly buffer Vertices { float v[]; } vertices;  // pos, normal
layout(set = 0, binding = 5, std430) writeonly buffer ProbeLight { vec4 v[]; } probeLight;
layout(push_constant) uniform Count { uint vertexCount; } pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.vertexCount) return;
    vec3 p = vec3(vertices.v[6 * i], vertices.v[6 * i + 1], vertices.v[6 * i + 2]);
    vec3 n = normalize(vec3(vertices.v[6 * i + 3], vertices.v[6 * i + 4], vertices.v[6 * i + 5]));
    float weight = 0.0;
    vec3 irradiance = probeIrradiance(p, n, weight);
    probeLight.v[i] = vec4(irradiance, weight);
}
