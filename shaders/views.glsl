// The debug views: kView<Name> constants from debug_views.def, one function per view, and the
// dispatch over them (include after tonemap.glsl, sky.glsl, brdf.glsl, shadows.glsl, fog.glsl,
// reflections.glsl and lpv.glsl). A view added to the list that has no function here fails the build.
#ifndef TLX_VIEWS_GLSL
#define TLX_VIEWS_GLSL

#define TLX_VIEW(NAME, NUMBER) const int kView##NAME = NUMBER;
#include "debug_views.def"
#undef TLX_VIEW

// What the views read at one terrain point.
struct ShadingPoint {
    vec3 position, normal, albedo;
    vec3 faceNormal;   // the drawn triangle's normal: the surface the shadow maps hold
    vec3 vertexNormal; // the mesh's normal interpolated from its vertices: which side of the
                       // terminator the point is on, as the traced sun visibility decides it
    // rgb probe irradiance, a blend weight; in the diagnostics views instead: x share of moved
    // probes in the blend (-1 where no probe lights the point), y interpolation error × known,
    // z known (1 = measured), w 1 = inside a volume with no probe to light it; in the
    // sun-visibility view: x the traced visibility.
    vec4 probe;
    float aoRaw;       // precomputed sky visibility (1 where none was computed)
    float ao;          // what darkens the sky light: aoRaw, or 1 with AO off
    float aoProbe;     // what darkens the probe light: the AO finer than the probes
    float variance;    // the normals' variance under the pixel (Toksvig)
    float roughness;   // GGX roughness after the variance
    float filled;      // share of filled nodata cells
    float shadow;      // sunShadow(): 1 lit, 0 in shadow
    float fogAmount;   // 1 − the fog's transmittance to the camera
    vec3 reflection;         // the reflection probes' radiance toward the mirror direction
    float reflectionWeight;  // their blend weight over the sky's: coverage fade × strength
    vec3 linear;       // sceneLinear(), seen through the fog
    LpvSample lpv;     // the LPV at the point (all cascades; cascade 0 alone in views 61-63)
    float lpvAo;       // view 63: cascade 0's geometry volume's ambient occlusion, 1 open
    float lpvCover;    // view 63: cascade 0's fade weight at the point, 0 outside it
    float lpvBlocking; // view 62: cascade 0's geometry, the share of light into the ground it stops
    float lpvExposure; // views 61 and 64: 1 / cascade 0's light range (lpv::lightRange), 0 without
};

float sunNdotL(ShadingPoint s) { return max(dot(s.normal, normalize(sunSky.sunDirection)), 0.0); }

// Scene-linear light leaving the point toward the camera: Lambert + GGX sun, sky irradiance
// (darkened by the AO) with the baked probe irradiance blended over it (absent probes leave the
// sky term as it is), and the environment's specular: the sky's radiance in the mirror direction
// through the split-sum environment BRDF, the AO standing in for specular occlusion (a sky the
// horizon hides is neither lit from nor reflected). Reflection probes replace the sky's radiance
// by their weight, darkened like the probe light by the AO finer than the probes (a weight of 0
// leaves the sky's term exactly as it is).
vec3 sceneLinear(ShadingPoint s) {
    vec3 n = s.normal;
    vec3 l = normalize(sunSky.sunDirection);
    vec3 v = normalize(camera.position - s.position);
    float ndotl = max(dot(n, l), 0.0);
    vec3 sky = skyIrradiance(n) * s.ao;
    float weight = s.probe.a;
    vec3 ambient = weight > 0.0 ? mix(sky, s.probe.rgb * s.aoProbe, weight) : sky;
    vec3 spec = ggxSpecular(n, v, l, s.roughness);
    vec3 environment = skyRadiance(reflect(-v, n)) * s.ao;
    if (s.reflectionWeight > 0.0) environment = mix(environment, s.reflection * s.aoProbe, s.reflectionWeight);
    // The LPV's bounce light adds to the sky's (lighting.indirect lpv) or to the probes' (both):
    // the LPV carries the sun's and the lights' first bounce only, never the sky.
#ifdef TLX_LPV
    if (kLpv && lpv.addsToAmbient > 0.5) {
        ambient += s.lpv.irradiance;
        environment += s.lpv.specular;
    }
#endif
    vec3 specEnv = envBrdf(kGroundF0, dot(n, v), s.roughness) * environment;
    // Probes hold no direct sun: the sun alone is shadowed by the cascades.
    vec3 sun = sunSky.sunIlluminance * s.shadow;
    vec3 color = s.albedo / PI * (sun * ndotl + ambient) + spec * sun + specEnv;
#ifdef TLX_LPV
    if (kLocalLights) color += localLightsDirect(s.position, n, v, s.albedo, s.roughness);
#endif
    return color;
}

vec3 viewBeauty(ShadingPoint s) { return display(s.linear); }
vec3 viewAlbedo(ShadingPoint s) { return linearOutput() ? s.albedo : srgb(s.albedo); }
vec3 viewNormal(ShadingPoint s) { return s.normal * 0.5 + 0.5; }
vec3 viewNdotL(ShadingPoint s) { return vec3(sunNdotL(s)); }
vec3 viewLinear(ShadingPoint s) { return linearOutput() ? s.linear : clamp(s.linear, 0.0, 1.0); }
vec3 viewProbeIrradiance(ShadingPoint s) { return display(s.probe.rgb * s.probe.a / PI); }
vec3 viewProbeWeight(ShadingPoint s) { return vec3(s.probe.a); }
vec3 viewReflectionColor(ShadingPoint s) { return display(s.reflection * s.reflectionWeight); }
vec3 viewReflectionWeight(ShadingPoint s) { return vec3(s.reflectionWeight); }

// Probe validity: grey where probes at their placement light the ground, cyan as moved probes
// take part, red inside a volume where no valid probe is left, dark outside.
vec3 viewProbeValidity(ShadingPoint s) {
    vec4 d = s.probe;
    float relief = 0.55 + 0.45 * max(s.normal.y, 0.0);
    vec3 base = d.w > 0.5  ? vec3(0.85, 0.12, 0.10)
              : d.x > -0.5 ? mix(vec3(0.72), vec3(0.10, 0.80, 1.0), clamp(d.x, 0.0, 1.0))
                           : vec3(0.18);
    return base * relief;
}

// The scalar views write the value in red and 1 in green (terrain) to EXR, grey to PNG.
vec3 scalarView(float value) { return linearOutput() ? vec3(value, 1.0, 0.0) : vec3(clamp(value, 0.0, 1.0)); }
vec3 viewAo(ShadingPoint s) { return scalarView(s.aoRaw); }
vec3 viewSunVisibility(ShadingPoint s) { return scalarView(s.probe.x); }
vec3 viewShadow(ShadingPoint s) { return scalarView(s.shadow); }
vec3 viewFog(ShadingPoint s) { return scalarView(s.fogAmount); }

vec3 cascadeColour(int c) {
    return c == 0 ? vec3(0.90, 0.25, 0.20) : c == 1 ? vec3(0.25, 0.75, 0.25)
         : c == 2 ? vec3(0.25, 0.45, 0.95) : c == 3 ? vec3(0.95, 0.85, 0.20) : vec3(0.45);
}

// Cascade index: red, green, blue, yellow for cascades 0-3, grey beyond the shadow distance, a
// dark line where one cascade hands over to the next and, before it, the two colours mixed where
// the shadows blend (shadows.cascade_blend), the last one's into grey where it fades out; shaded
// by N·L so the terrain stays legible.
vec3 viewCascades(ShadingPoint s) {
    int c = sunCascade(s.position);
    vec3 base = mix(cascadeColour(c), cascadeColour(nextCascade(c)), cascadeBlendWeight(s.position, c));
    if (nearCascadeBoundary(s.position)) return vec3(0.02);
    return base * (0.45 + 0.55 * sunNdotL(s));
}

// Interpolation error: EXR holds the error in red and 1 in green where measured.
vec3 viewInterpolationError(ShadingPoint s) {
    float known = s.probe.z;
    float error = known > 0.0 ? s.probe.y / known : 0.0;
    if (linearOutput()) return vec3(known > 0.5 ? error : 0.0, known > 0.5 ? 1.0 : 0.0, 0.0);
    return (known > 0.5 ? heat(error) : vec3(0.25)) * (0.75 + 0.25 * max(s.normal.y, 0.0));
}

// Normal variance: EXR holds σ² in red; PNG the heat ramp (0.1 and above red), shaded by N·L.
vec3 viewNormalVariance(ShadingPoint s) {
    if (linearOutput()) return vec3(s.variance, 1.0, 0.0);
    return heat(s.variance) * (0.6 + 0.4 * sunNdotL(s));
}

// Filled voids: the final image with filled cells tinted magenta.
vec3 viewFilled(ShadingPoint s) {
    vec3 c = display(s.linear);
    float luma = rec709Luminance(c.r, c.g, c.b);
    return mix(c, vec3(1.0, 0.1, 0.9) * (0.35 + 0.65 * luma), 0.75 * clamp(s.filled, 0.0, 1.0));
}

// The water views on land (the water pass draws the water): the mask's land colour, no distance
// to shore, and the land's normal in the water-normal view.
vec3 viewWaterMask(ShadingPoint s) {
    return linearOutput() ? vec3(0.0, 1.0, 0.0) : vec3(0.32, 0.27, 0.20) * (0.6 + 0.4 * sunNdotL(s));
}
vec3 viewShoreDistance(ShadingPoint s) { return linearOutput() ? vec3(0.0, 0.0, 0.0) : vec3(0.0); }
vec3 viewWaterNormal(ShadingPoint s) { return vec3(0.5) * (0.6 + 0.4 * sunNdotL(s)); }

// The LPV views: the irradiance of cascade 0 alone and of all cascades blended, as E/π (a white
// Lambertian surface's radiance). EXR holds E/π as it is; PNG shows it with the views' own exposure
// (not the camera's): E/π over cascade 0's light range, the same scale for both views so they can be
// told apart, through the display curve. Cascade 0's geometry volume and its ambient occlusion as
// scalars. Black where the frame holds no LPV.
vec3 lpvDisplay(vec3 radiance, float exposure) {
    return linearOutput() ? radiance : srgb(aces(radiance * exposure));
}
vec3 viewLpvCascade0(ShadingPoint s) { return lpvDisplay(s.lpv.irradiance / PI, s.lpvExposure); }
vec3 viewLpvAll(ShadingPoint s) { return lpvDisplay(s.lpv.irradiance / PI, s.lpvExposure); }
vec3 viewLpvGeometry(ShadingPoint s) {
    if (linearOutput()) return vec3(s.lpvBlocking, 1.0, 0.0);
    return heat(0.1 * s.lpvBlocking) * (0.6 + 0.4 * sunNdotL(s));
}
vec3 viewLpvAo(ShadingPoint s) {
    if (linearOutput()) return vec3(s.lpvAo, s.lpvCover > 0.0 ? 1.0 : 0.0, 0.0);
    return vec3(clamp(s.lpvAo, 0.0, 1.0) * s.lpvCover);  // fading to black with the cascade, as view 61
}

vec3 shadeView(int view, ShadingPoint s) {
    // Once for every view: a CPU driver runs every branch of a switch under a mask, so the two
    // views that need the full shading share one evaluation.
    // The terminator by the mesh's own normal, not the filtered normal map's: the shading's n·l
    // darkens whatever faces away by the shading normal anyway, and the traced visibility this
    // factor is measured against decides it per vertex.
    s.shadow = sunShadow(s.position, s.vertexNormal, s.faceNormal);
    vec3 toPoint = s.position - camera.position;
    float distance = length(toPoint);
    vec3 dir = toPoint / max(distance, 1e-6);
    s.fogAmount = 1.0 - fogTransmittance(dir, distance);
    s.reflectionWeight = reflectionWeight(s.position);
    s.reflection = s.reflectionWeight > 0.0 ? reflectionProbeRadiance(s.position, reflect(dir, s.normal), s.roughness)
                                            : vec3(0.0);
    s.lpv.irradiance = vec3(0.0);
    s.lpv.specular = vec3(0.0);
    s.lpvAo = 1.0;
    s.lpvCover = 0.0;
    s.lpvBlocking = 0.0;
    s.lpvExposure = 0.0;
#ifdef TLX_LPV
    if (kLpv && lpv.cascadeCount > 0) {
        s.lpvExposure = lpv.viewExposure;
        bool firstOnly = view == kViewLpvCascade0 || view == kViewLpvGeometry || view == kViewLpvAo;
        int last = firstOnly ? 0 : lpv.cascadeCount - 1;
        s.lpv = lpvEvaluate(s.position, s.normal, -dir, lpv.quality, last);
        if (view == kViewLpvGeometry) s.lpvBlocking = clamp(lpvShEvaluate(lpvGeometryAt(s.position, 0), s.normal), 0.0, 1.0);
        if (view == kViewLpvAo) {
            float cell;
            s.lpvCover = lpvWeight(s.position, 0, cell);
            s.lpvAo = lpvAmbientOcclusion(s.position, s.normal, 0);
        }
    }
#endif
    s.linear = applyFog(sceneLinear(s), dir, distance);
    switch (view) {
#define TLX_VIEW(NAME, NUMBER) case kView##NAME: return view##NAME(s);
#include "debug_views.def"
#undef TLX_VIEW
    }
    return viewBeauty(s);
}

#endif
