// Reflection probes (docs/lighting.md, "Reflection probes in the renderer"): the grid's coverage
// weight at a point and the probes' prefiltered radiance toward a direction, read the way
// ReflectionProbeSet::evaluate (renderer/bake/ReflectionBake.h) reads them. Built with
// TLX_REFLECTIONS the lights set holds the probes; without, no point is covered (weight 0) and
// nothing of them is declared. Include after blocks/glsl.h.
#ifndef TLX_REFLECTIONS_GLSL
#define TLX_REFLECTIONS_GLSL

#ifdef TLX_REFLECTIONS
#include "blocks/reflections.h"
layout(set = TLX_SET_LIGHTS, binding = TLX_REFLECTION_PROBES_BINDING, std430) readonly buffer ReflectionProbes {
    ReflectionProbeRecord p[];
} reflectionProbes;
layout(set = TLX_SET_LIGHTS, binding = TLX_REFLECTION_CUBES_BINDING) uniform samplerCubeArray reflectionCubes;

// The blend weight of the grid at p, strength included: 1 over the coverage rectangle (the
// probes' cells, first probe − cell/2 to last probe + cell/2 in x and z), fading linearly to 0 at
// the fallback blend distance outside it, like a probe volume's fade (probes.glsl).
float reflectionWeight(vec3 p) {
    vec2 lo = reflection.origin - 0.5 * reflection.cellSize;
    vec2 hi = reflection.origin + reflection.spacing * vec2(ivec2(reflection.nx, reflection.nz) - 1) + 0.5 * reflection.cellSize;
    float dist = length(p.xz - clamp(p.xz, lo, hi));
    float fallback = reflection.blendDistance;
    float fade = dist <= 0.0 ? 1.0 : (fallback > 0.0 ? clamp(1.0 - dist / fallback, 0.0, 1.0) : 0.0);
    return fade * reflection.strength;
}

// Parallax-corrected lookup direction (Lagarde and Zanuttini, "Local Image-based Lighting With
// Parallax-corrected Cubemap", SIGGRAPH 2012): where the ray p + t·r leaves the probe's box, as
// seen from the capture point. From outside the box the probe is read along r itself.
vec3 boxProjected(ReflectionProbeRecord probe, vec3 p, vec3 r) {
    vec3 q = p - probe.position, e = probe.halfExtent;
    if (any(greaterThan(abs(q), e))) return r;
    // 1/r without infinities: an axis the ray barely moves along exits last.
    vec3 inv = vec3(r.x < 0.0 ? -1.0 : 1.0, r.y < 0.0 ? -1.0 : 1.0, r.z < 0.0 ? -1.0 : 1.0) / max(abs(r), vec3(1e-6));
    vec3 exits = max((e - q) * inv, (-e - q) * inv);
    return q + min(min(exits.x, exits.y), exits.z) * r;
}

// Probe i's prefiltered radiance toward d for GGX `roughness`. Faces: the ambient cube
// Σ d_i² · face(sign d_i, i), the same at every roughness. Cubemap: cube i of the array at lod
// roughness × (mips − 1); the sampler picks the face (Vulkan's cube-face selection, the bake's
// convention), filters bilinearly across face edges too and linearly between the two mips.
vec3 probeRadiance(int i, vec3 d, float roughness) {
    d = normalize(d);
    if (reflection.encoding == 0) {
        vec3 d2 = d * d;
        return d2.x * reflectionProbes.p[i].faces[d.x < 0.0 ? 1 : 0].rgb +
               d2.y * reflectionProbes.p[i].faces[d.y < 0.0 ? 3 : 2].rgb +
               d2.z * reflectionProbes.p[i].faces[d.z < 0.0 ? 5 : 4].rgb;
    }
    float lod = clamp(roughness, 0.0, 1.0) * float(reflection.mipLevels - 1);
    return textureLod(reflectionCubes, vec4(d, float(i)), lod).rgb;
}

// Where p lies on the probe lattice, in probes from probe 0 (0 on a one-probe axis).
vec2 reflectionLattice(vec3 p) {
    vec2 spacing = reflection.spacing;
    vec2 g = vec2(spacing.x > 0.0 ? (p.x - reflection.origin.x) / spacing.x : 0.0,
                  spacing.y > 0.0 ? (p.z - reflection.origin.y) / spacing.y : 0.0);
    return clamp(g, vec2(0.0), vec2(ivec2(reflection.nx, reflection.nz) - 1));
}

// The probes' radiance reflected at p along r: bilinear over the 4 probes around p (clamped at
// the grid's ends), each box-projected on its own.
vec3 reflectionProbeRadiance(vec3 p, vec3 r, float roughness) {
    ivec2 n = ivec2(reflection.nx, reflection.nz);
    vec2 g = reflectionLattice(p);
    ivec2 i0 = min(ivec2(floor(g)), max(n - 2, ivec2(0)));
    vec2 f = g - vec2(i0);
    vec3 sum = vec3(0.0);
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        ivec2 c = min(i0 + o, n - 1);
        vec2 w2 = mix(vec2(1.0) - f, f, vec2(o));
        float w = w2.x * w2.y;
        if (w <= 0.0) continue;
        int i = c.y * n.x + c.x;
        sum += w * probeRadiance(i, boxProjected(reflectionProbes.p[i], p, r), roughness);
    }
    return sum;
}

// The nearest probe's radiance at p along r (the water's reflection), box-projected.
vec3 nearestReflectionProbeRadiance(vec3 p, vec3 r, float roughness) {
    ivec2 c = ivec2(floor(reflectionLattice(p) + 0.5));
    int i = c.y * reflection.nx + c.x;
    return probeRadiance(i, boxProjected(reflectionProbes.p[i], p, r), roughness);
}
#else
float reflectionWeight(vec3 p) { return 0.0; }
vec3 reflectionProbeRadiance(vec3 p, vec3 r, float roughness) { return vec3(0.0); }
vec3 nearestReflectionProbeRadiance(vec3 p, vec3 r, float roughness) { return vec3(0.0); }
#endif

#endif
