#version 450
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
// From probe_vertices.comp: irradiance and weight, or in views 54 and 56 the diagnostics.
layout(location = 2) in vec4 inProbeLight;
layout(location = 0) out vec3 worldPos;
layout(location = 1) out vec3 worldNormal;
// Probe irradiance is smooth at the scale of the mesh: evaluated per vertex (the mesh vertices are
// the DEM samples, or every k-th under the vertex budget) and interpolated.
layout(location = 2) out vec4 probeIrradianceWeight;

void main() {
    worldPos = inPosition;
    worldNormal = inNormal;
    bool diagnostics = frame.params.x == 54 || frame.params.x == 56;
    probeIrradianceWeight = frame.params.z == 1 ? inProbeLight
                          : diagnostics         ? vec4(-1.0, 0.0, 0.0, 0.0)  // no probe lights it
                                                : vec4(0.0);
    gl_Position = frame.viewProj * vec4(inPosition, 1.0);
}
