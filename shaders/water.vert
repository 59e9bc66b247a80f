#version 450
#extension GL_GOOGLE_include_directive : require
// The water mesh: a grid at rest on the plane, moved by the waves long enough for its spacing
// (the shorter ones live in the fragment shader's normal only).
#include "blocks/glsl.h"
#include "blocks/camera.h"
#include "blocks/surface.h"
#include "blocks/water.h"
#include "sh.glsl"
#include "water.glsl"

layout(location = 0) in vec2 inRest;  // (x, z) on the plane
layout(location = 0) out vec3 restPos;
layout(location = 1) out vec3 worldPos;

void main() {
    vec2 field = waterFieldAt(inRest);
    vec3 displacement, normal;
    // Two vertices per wavelength at the least (Nyquist) for a wave to move the mesh.
    gerstner(inRest, max(field.x, 0.0), shoreFade(field.y), 2.0 * water.meshSpacing, displacement, normal);
    restPos = vec3(inRest.x, water.level, inRest.y);
    worldPos = restPos + displacement;
    gl_Position = camera.viewProj * vec4(worldPos, 1.0);
}
