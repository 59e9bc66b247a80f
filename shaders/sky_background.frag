#version 450
#extension GL_GOOGLE_include_directive : require
// The sky behind the terrain: its radiance toward each pixel's view ray (the sky image at full
// resolution for an hdr or physical sky, the SH of a uniform one), the sun's disc, and the fog
// between (docs/lighting.md, "Height fog": the sky through all the fog a rising ray crosses; the
// far plane's share where the fog has no top). Below the horizon, with the skirt on, the ground
// the bake traces beyond the footprint: level ground at the border's mean height and albedo, lit
// as the bake lights its skirt, fogged over its own distance, so it fades into the haze toward
// the horizon, where the sky's fog meets it. With the skirt off (or a camera below that ground)
// the horizon's radiance, as rays that escape the footprint see (the image's own below it).
#include "blocks/glsl.h"
#include "blocks/camera.h"
#include "blocks/surface.h"
#include "blocks/sun_sky.h"
#include "blocks/atmosphere.h"
#include "sh.glsl"
#include "sky.glsl"
#include "tonemap.glsl"
#include "fog.glsl"
#include "sky_math.glsl"

layout(set = TLX_SET_VIEW, binding = TLX_SKY_IMAGE_BINDING) uniform sampler2D skyImageMap;

// The sky image toward d (hdr, physical): its own texels at the level a pixel spans, through the
// mapping the bake samples it with.
vec3 skyImageRadiance(vec3 d) {
    vec2 uv = vec2(equirectU(d.x, d.z, surface.skyImageRotation), equirectV(d.y));
    return surface.skyImageScale * textureLod(skyImageMap, uv, surface.skyImageLod).rgb;
}

layout(location = 0) in vec2 ndc;
layout(location = 0) out vec4 outColor;

void main() {
    vec4 far = camera.invViewProj * vec4(ndc, 0.0, 1.0);  // reversed Z: depth 0 is the far plane
    vec3 dir = normalize(far.xyz / far.w - camera.position);
    vec3 l = normalize(sunSky.sunDirection);
    float above = camera.position.y - surface.groundHeight;
    vec3 radiance;
    if (surface.ground > 0.5 && dir.y < 0.0 && above > 0.0) {
        // Open level ground: the sky's irradiance on a level surface plus the sun, unshadowed.
        vec3 irradiance = skyIrradiance(vec3(0.0, 1.0, 0.0)) + sunSky.sunIlluminance * max(l.y, 0.0);
        radiance = applyFog(surface.groundAlbedo / PI * irradiance, dir, above / -dir.y);
    } else {
        radiance = surface.skyImage > 0.5 ? skyImageRadiance(dir) : skyRadiance(dir);
        // The sun's disc: its illuminance spread over the disc's solid angle π·r².
        float r = sunSky.sunAngularRadius;
        if (r > 0.0 && dir.y > 0.0 && dot(dir, l) >= cos(r))
            radiance += sunSky.sunIlluminance / (PI * r * r);
        radiance = applySkyFog(radiance, dir);
    }
    outColor = vec4(display(radiance), 1.0);
}
