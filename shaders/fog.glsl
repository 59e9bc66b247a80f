// Exponential height fog on what the camera sees (docs/lighting.md, "Height fog"). Include after
// blocks/camera.h, blocks/sun_sky.h and blocks/atmosphere.h. The scene's fog flag is a
// specialisation constant: a scene without fog compiles the code out.
#ifndef TLX_FOG_GLSL
#define TLX_FOG_GLSL

#include "fog_math.glsl"

layout(constant_id = 0) const int kFogEnabled = 0;
const bool kFog = kFogEnabled != 0;

// Transmittance from the camera to a point `distance` metres along the unit view ray `dir`.
float fogTransmittance(vec3 dir, float distance) {
    if (!kFog) return 1.0;
    float depth = fogOpticalDepth(atmosphere.fogDensity, atmosphere.fogFalloff, camera.position.y - atmosphere.fogBase,
                                  dir.y, distance);
    return exp(-depth);
}

// Light the fog scatters toward the camera over a segment of transmittance t: the ambient
// radiance, plus the sun through the Henyey–Greenstein phase (single scattering, albedo 1, the
// sun unshadowed inside the fog).
vec3 fogInscatter(vec3 dir, float t) {
    float cosTheta = dot(dir, normalize(sunSky.sunDirection));
    vec3 sun = sunSky.sunIlluminance * atmosphere.sunInscatter * henyeyGreenstein(atmosphere.fogAnisotropy, cosTheta);
    return (1.0 - t) * (atmosphere.fogColor + sun);
}

// Scene-linear light of the sky toward `dir` seen through the fog (fogSkyOpticalDepth).
vec3 applySkyFog(vec3 radiance, vec3 dir) {
    if (!kFog) return radiance;
    // Past a depth of 80 the transmittance is 0 in float; the horizon's depth is unbounded.
    float depth = fogSkyOpticalDepth(atmosphere.fogDensity, atmosphere.fogFalloff,
                                     camera.position.y - atmosphere.fogBase, dir.y, camera.farPlane);
    float t = exp(-min(depth, 80.0));
    return radiance * t + fogInscatter(dir, t);
}

// Scene-linear light of a point seen through the fog.
vec3 applyFog(vec3 radiance, vec3 dir, float distance) {
    if (!kFog) return radiance;
    float t = fogTransmittance(dir, distance);
    return radiance * t + fogInscatter(dir, t);
}

#endif
