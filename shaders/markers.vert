#version 450
#extension GL_GOOGLE_include_directive : require
// Probe-position overlay: one screen-facing square per probe instance, a fixed size in pixels.
// Diffuse probes and reflection probes share it, told apart by colour.
#include "blocks/glsl.h"
#include "blocks/camera.h"
#include "blocks/overlay.h"

// xyz position, w 1 = valid, 2 = moved up, 0 = inside the terrain, 3 = a reflection probe
layout(location = 0) in vec4 inProbe;
layout(location = 0) out vec3 color;

void main() {
    const vec2 corners[6] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(1, 1),
                                   vec2(-1, -1), vec2(1, 1), vec2(-1, 1));
    vec4 clip = camera.viewProj * vec4(inProbe.xyz, 1.0);
    clip.xy += corners[gl_VertexIndex % 6] * overlay.markerPixels / camera.viewportSize * 2.0 * clip.w;
    gl_Position = clip;
    bool reflection = inProbe.w > 2.5;
    bool valid = reflection || (inProbe.w > 0.5 && inProbe.w < 1.5);
    if (valid ? overlay.drawValid == 0 : overlay.drawMovedRejected == 0)
        gl_Position = vec4(0.0, 0.0, 2.0, 1.0);  // outside the depth range: clipped
    // Valid gold, moved cyan, rejected red; reflection probes violet (apart from all three).
    color = reflection ? vec3(0.70, 0.30, 1.0)
          : inProbe.w > 1.5 ? vec3(0.10, 0.80, 1.0) : inProbe.w > 0.5 ? vec3(1.0, 0.85, 0.1) : vec3(1.0, 0.1, 0.1);
}
