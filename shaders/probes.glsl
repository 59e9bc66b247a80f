// Probe lighting: the probe pass's buffers and the engine's probe lookup (include after
// blocks/glsl.h, blocks/probes.h and sh.glsl).
#ifndef TLX_PROBES_GLSL
#define TLX_PROBES_GLSL

// 9 per probe, RGB in xyz; coeffs[9 i].w = 1 when probe i was moved up out of the terrain.
layout(set = TLX_SET_SUBSYSTEM, binding = 1, std430) readonly buffer Probes { vec4 coeffs[]; } probes;
layout(set = TLX_SET_SUBSYSTEM, binding = 2, std430) readonly buffer Cells { int cell[]; } cells;
layout(set = TLX_SET_SUBSYSTEM, binding = 3, std430) readonly buffer Volumes { ProbeVolumeRecord v[]; } volumes;

int cellIndex(ProbeVolumeRecord vol, ivec3 c) {
    return vol.firstCell + c.x + c.y * vol.dims.x + c.z * vol.dims.x * vol.dims.y;
}

// Probe irradiance at p: trilinear over the centres of the .shprobe occupancy cells around p
// (cells with no probe drop out and the rest renormalise). Below the occupied cells, as at a
// terrain surface point, the lookup climbs to the first layer that has probes. The returned
// weight fades from 1 at the grid box to 0 at the fallback blend distance outside it; the first
// volume with any weight wins, as engines take the first grid that contains a point.
// Also: the blended share of moved probes, the volume that lit p (-1: none), and whether p lies
// inside some volume's box with no probe to light it.
vec3 probeIrradiance(vec3 p, vec3 n, out float weight, out float movedShare, out int volume,
                     out bool unlit) {
    weight = 0.0;
    movedShare = 0.0;
    volume = -1;
    unlit = false;
    bool inBox = false;
    for (int vi = 0; vi < probeSet.volumeCount; ++vi) {
        ProbeVolumeRecord vol = volumes.v[vi];
        vec3 lo = vol.origin;
        float h = vol.spacing;
        ivec3 dims = vol.dims;
        vec3 hi = lo + h * vec3(dims);
        vec3 q = clamp(p, lo, hi);
        float dist = length(p - q);
        float fallback = vol.fallbackBlend;
        float fade = dist <= 0.0 ? 1.0 : (fallback > 0.0 ? clamp(1.0 - dist / fallback, 0.0, 1.0) : 0.0);
        if (fade <= 0.0) continue;
        vec3 g = (q - lo) / h - 0.5;
        ivec3 c0 = ivec3(floor(g));
        vec3 f = g - vec3(c0);
        for (int climb = 0; climb < dims.y + 1; ++climb) {
            // Blend the corner probes' coefficients, then evaluate once: irradiance is linear in
            // the coefficients, and one evaluation costs what eight would not.
            vec3 blended[9];
            for (int j = 0; j < 9; ++j) blended[j] = vec3(0.0);
            float wsum = 0.0, moved = 0.0;
            for (int k = 0; k < 8; ++k) {
                ivec3 o = ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
                ivec3 c = clamp(c0 + o + ivec3(0, climb, 0), ivec3(0), dims - 1);
                int probe = cells.cell[cellIndex(vol, c)];
                if (probe < 0) continue;
                vec3 wv = mix(vec3(1.0) - f, f, vec3(o));
                float w = max(wv.x * wv.y * wv.z, 1e-6);  // a corner on a cell centre still counts
                int base = (vol.firstProbe + probe) * 9;
                for (int j = 0; j < 9; ++j) blended[j] += w * probes.coeffs[base + j].rgb;
                moved += w * probes.coeffs[base].w;
                wsum += w;
            }
            if (wsum > 0.0) {
                weight = fade;
                movedShare = moved / wsum;
                volume = vi;
                for (int j = 0; j < 9; ++j) blended[j] /= wsum;
                return max(shIrradiance(blended, n, vol.preConvolved == 1) * vol.shScale, vec3(0.0));
            }
        }
        inBox = inBox || dist <= 0.0;
    }
    unlit = inBox;  // no volume lit p, and one of them contains it
    return vec3(0.0);
}

#endif
