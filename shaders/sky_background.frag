#version 450
#extension GL_GOOGLE_include_directive : require
// The sky behind the terrain: its radiance toward each pixel's view ray (from the sky's SH, the
// horizon's below the horizon), the sun's disc, and the fog between (docs/lighting.md, "Height
// fog": the sky is fogged at the far plane, so the horizon blends into the haze).
#include "blocks/glsl.h"
#include "blocks/camera.h"
#include "blocks/surface.h"
#include "blocks/sun_sky.h"
#include "blocks/atmosphere.h"
#include "sh.glsl"
#include "sky.glsl"
#include "tonemap.glsl"
#include "fog.glsl"

layout(location = 0) in vec2 ndc;
layout(location = 0) out vec4 outColor;

void main() {
    vec4 far = camera.invViewProj * vec4(ndc, 0.0, 1.0);  // reversed Z: depth 0 is the far plane
    vec3 dir = normalize(far.xyz / far.w - camera.position);
    vec3 radiance = skyRadiance(dir);
    // The sun's disc: its illuminance spread over the disc's solid angle π·r².
    float r = sunSky.sunAngularRadius;
    vec3 l = normalize(sunSky.sunDirection);
    if (r > 0.0 && dir.y > 0.0 && dot(dir, l) >= cos(r))
        radiance += sunSky.sunIlluminance / (PI * r * r);
    radiance = applyFog(radiance, dir, camera.farPlane);
    outColor = vec4(display(radiance), 1.0);
}
