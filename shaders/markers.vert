#version 450
#extension GL_GOOGLE_include_directive : require
// Probe-position overlay: one screen-facing square per probe instance, a fixed size in pixels.
#include "frame.glsl"

layout(location = 0) in vec4 inProbe;  // xyz position, w 1 = valid, 2 = moved up, 0 = inside the terrain
layout(location = 0) out vec3 color;

void main() {
    const vec2 corners[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(1, 1),
                                   vec2(-1, -1), vec2(1, 1), vec2(-1, 1));
    vec4 clip = frame.viewProj * vec4(inProbe.xyz, 1.0);
    vec2 pixels = frame.exposure.zw;  // viewport size
    clip.xy += corners[gl_VertexIndex % 6] * 3.0 / pixels * 2.0 * clip.w;
    gl_Position = clip;
    // View 54 marks the moved and rejected probes; the valid ones only with the overlay on.
    if (frame.params.x == 54 && frame.overlay.y < 0.5 && inProbe.w > 0.5 && inProbe.w < 1.5)
        gl_Position = vec4(0.0, 0.0, 2.0, 1.0);  // beyond the far plane: clipped
    // The palette of view 54: valid gold, moved cyan, rejected red.
    color = inProbe.w > 1.5 ? vec3(0.10, 0.80, 1.0) : inProbe.w > 0.5 ? vec3(1.0, 0.85, 0.1) : vec3(1.0, 0.1, 0.1);
}
