// Surface reflectance (include after sh.glsl for PI).
#ifndef TLX_BRDF_GLSL
#define TLX_BRDF_GLSL

// GGX (Walter et al. 2007) with Schlick Fresnel of reflectance f0 at normal incidence and the
// Smith-Schlick visibility term, times N·L: the specular response to a light of unit illuminance
// from l.
vec3 ggxSpecularF0(vec3 n, vec3 v, vec3 l, float roughness, float f0) {
    float ndotl = max(dot(n, l), 0.0);
    float a = roughness * roughness;
    vec3 hv = normalize(l + v);
    float ndoth = max(dot(n, hv), 0.0), ndotv = max(dot(n, v), 1e-4);
    float d = a * a / (PI * pow(ndoth * ndoth * (a * a - 1.0) + 1.0, 2.0));
    float k = a * 0.5;
    float g = ndotl / (ndotl * (1.0 - k) + k) * ndotv / (ndotv * (1.0 - k) + k);
    float fres = f0 + (1.0 - f0) * pow(1.0 - max(dot(hv, v), 0.0), 5.0);
    return vec3(d * g * fres / max(4.0 * ndotl * ndotv, 1e-4)) * ndotl;
}
// Dielectric ground: f0 = 0.04.
const float kGroundF0 = 0.04;
vec3 ggxSpecular(vec3 n, vec3 v, vec3 l, float roughness) { return ggxSpecularF0(n, v, l, roughness, kGroundF0); }

// The split-sum environment BRDF, f0·A + B: the share of the environment's prefiltered radiance
// a GGX surface of roughness r reflects toward v, in the analytic fit of Karis, "Physically Based
// Shading on Mobile" (2014), to the same Smith-Schlick GGX as above.
float envBrdf(float f0, float ndotv, float roughness) {
    const vec4 c0 = vec4(-1.0, -0.0275, -0.572, 0.022);
    const vec4 c1 = vec4(1.0, 0.0425, 1.04, -0.04);
    vec4 r = roughness * c0 + c1;
    float a004 = min(r.x * r.x, exp2(-9.28 * max(ndotv, 0.0))) * r.x + r.y;
    vec2 ab = vec2(-1.04, 1.04) * a004 + r.zw;
    return f0 * ab.x + ab.y;
}

#endif
