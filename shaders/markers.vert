#version 450
#extension GL_GOOGLE_include_directive : require
// Probe-position overlay: one screen-facing square per probe instance, a fixed size in pixels.
#include "frame.glsl"

layout(location = 0) in vec4 inProbe;  // xyz position, w 1 = valid, 0 = inside the terrain
layout(location = 0) out vec3 color;

void main() {
    const vec2 corners[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(1, 1),
                                   vec2(-1, -1), vec2(1, 1), vec2(-1, 1));
    vec4 clip = frame.viewProj * vec4(inProbe.xyz, 1.0);
    vec2 pixels = frame.exposure.zw;  // viewport size
    clip.xy += corners[gl_VertexIndex % 6] * 3.0 / pixels * 2.0 * clip.w;
    gl_Position = clip;
    color = inProbe.w > 0.5 ? vec3(1.0, 0.85, 0.1) : vec3(1.0, 0.1, 0.1);
}
