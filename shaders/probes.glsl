// Probe lighting shared by the terrain stages (include after frame.glsl).

const float PI = 3.14159265358979;

// Irradiance of SH radiance coefficients for normal n: Σ Â_l L_k Y_k(n) (Ramamoorthi and
// Hanrahan 2001), basis of FORMATS.md. `convolved` = the coefficients already hold Â_l L_k.
vec3 shIrradiance(vec3 c[9], vec3 n, bool convolved) {
    float y[9];
    y[0] = 0.282095;
    y[1] = 0.488603 * n.y;
    y[2] = 0.488603 * n.z;
    y[3] = 0.488603 * n.x;
    y[4] = 1.092548 * n.x * n.y;
    y[5] = 1.092548 * n.y * n.z;
    y[6] = 0.315392 * (3.0 * n.z * n.z - 1.0);
    y[7] = 1.092548 * n.x * n.z;
    y[8] = 0.546274 * (n.x * n.x - n.y * n.y);
    const float a0 = convolved ? 1.0 : PI, a1 = convolved ? 1.0 : 2.0 * PI / 3.0,
                a2 = convolved ? 1.0 : PI / 4.0;
    vec3 e = a0 * c[0] * y[0];
    for (int k = 1; k < 4; ++k) e += a1 * c[k] * y[k];
    for (int k = 4; k < 9; ++k) e += a2 * c[k] * y[k];
    return e;
}

vec3 skyIrradiance(vec3 n) {
    vec3 c[9];
    for (int k = 0; k < 9; ++k) c[k] = frame.skySh[k].rgb;
    return max(shIrradiance(c, n, false), vec3(0.0));
}

int cellIndex(Volume vol, ivec3 c) {
    return vol.occupancy.x + c.x + c.y * vol.dimsProbe.x + c.z * vol.dimsProbe.x * vol.dimsProbe.y;
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
    for (int vi = 0; vi < frame.params.y; ++vi) {
        Volume vol = volumes.v[vi];
        vec3 lo = vol.originSpacing.xyz;
        float h = vol.originSpacing.w;
        ivec3 dims = vol.dimsProbe.xyz;
        vec3 hi = lo + h * vec3(dims);
        vec3 q = clamp(p, lo, hi);
        float dist = length(p - q);
        float fallback = vol.blend.x;
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
                int base = (vol.dimsProbe.w + probe) * 9;
                for (int j = 0; j < 9; ++j) blended[j] += w * probes.coeffs[base + j].rgb;
                moved += w * probes.coeffs[base].w;
                wsum += w;
            }
            if (wsum > 0.0) {
                weight = fade;
                movedShare = moved / wsum;
                volume = vi;
                for (int j = 0; j < 9; ++j) blended[j] /= wsum;
                return max(shIrradiance(blended, n, vol.occupancy.y == 1) * vol.blend.y, vec3(0.0));
            }
        }
        inBox = inBox || dist <= 0.0;
    }
    unlit = inBox;  // no volume lit p, and one of them contains it
    return vec3(0.0);
}
