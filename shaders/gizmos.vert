#version 450
#extension GL_GOOGLE_include_directive : require
// Gizmo lines (volume bounds and handles): one line per instance, two vertices, in the colour the
// host chose; the pipeline ignores depth so they stay visible behind the terrain.
#include "blocks/glsl.h"
#include "blocks/camera.h"

layout(location = 0) in vec4 inA;
layout(location = 1) in vec4 inB;
layout(location = 2) in vec4 inColor;
layout(location = 0) out vec3 color;

void main() {
    gl_Position = camera.viewProj * vec4(gl_VertexIndex % 2 == 0 ? inA.xyz : inB.xyz, 1.0);
    color = inColor.rgb;
}
