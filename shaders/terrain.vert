#version 450
#extension GL_GOOGLE_include_directive : require
// Built twice: with TLX_PROBE_LIGHT, probe light per vertex comes in as an attribute from the
// probe pass; without, the terrain binds nothing of the probes (a scene without them, or a view
// or frame that does not use them) and every vertex gets what "no probe" means.
#include "blocks/glsl.h"
#include "blocks/camera.h"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
#ifdef TLX_PROBE_LIGHT
// From probe_vertices.comp: irradiance and weight, or the diagnostics (camera.vertexAttribute).
layout(location = 2) in vec4 inProbeLight;
#endif
layout(location = 0) out vec3 worldPos;
layout(location = 1) out vec3 worldNormal;
// Probe irradiance is smooth at the scale of the mesh: evaluated per vertex (the mesh vertices are
// the DEM samples, or every k-th under the vertex budget) and interpolated.
layout(location = 2) out vec4 probeIrradianceWeight;

void main() {
    worldPos = inPosition;
    worldNormal = inNormal;
#ifdef TLX_PROBE_LIGHT
    probeIrradianceWeight = inProbeLight;
#else
    // No light, weight 0; in the diagnostics: no probe lights the point.
    probeIrradianceWeight = camera.vertexAttribute == 1 ? vec4(-1.0, 0.0, 0.0, 0.0) : vec4(0.0);
#endif
    gl_Position = camera.viewProj * vec4(inPosition, 1.0);
}
