#version 450
#extension GL_GOOGLE_include_directive : require
// Terrain shading (docs/lighting.md) and the debug views. It binds the view and the lights only: probe
// light comes in per vertex from the probe pass, when there is one. Built twice: with
// TLX_SHADOWS the lights include the sun's shadow cascades.
#include "blocks/glsl.h"
#include "blocks/camera.h"
#include "blocks/surface.h"
#include "blocks/sun_sky.h"
#include "blocks/atmosphere.h"
#include "sh.glsl"
#include "sky.glsl"
#include "brdf.glsl"
#include "tonemap.glsl"
#include "shadows.glsl"
#include "fog.glsl"
#include "views.glsl"

layout(location = 0) in vec3 worldPos;
layout(location = 1) in vec3 worldNormal;
layout(location = 2) in vec4 probeIrradianceWeight;  // ShadingPoint.probe
layout(location = 0) out vec4 outColor;

void main() {
    ShadingPoint s;
    s.position = worldPos;
    s.normal = normalize(worldNormal);
    s.albedo = surface.albedo.rgb;
    s.probe = probeIrradianceWeight;
    outColor = vec4(shadeView(camera.view.x, s), 1.0);
}
