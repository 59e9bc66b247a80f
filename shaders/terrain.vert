#version 450
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inProbeLight;  // from probe_vertices.comp
layout(location = 3) in vec4 inProbeInfo;   // moved share, error, error known, unlit
layout(location = 0) out vec3 worldPos;
layout(location = 1) out vec3 worldNormal;
// Probe irradiance is smooth at the scale of the mesh: evaluated per vertex (the mesh vertices are
// the DEM samples, or every k-th under the vertex budget) and interpolated.
layout(location = 2) out vec4 probeIrradianceWeight;
layout(location = 3) out vec4 probeInfo;

void main() {
    worldPos = inPosition;
    worldNormal = inNormal;
    probeIrradianceWeight = frame.params.z == 1 ? inProbeLight : vec4(0.0);
    probeInfo = frame.params.z == 1 ? inProbeInfo : vec4(0.0);
    gl_Position = frame.viewProj * vec4(inPosition, 1.0);
}
