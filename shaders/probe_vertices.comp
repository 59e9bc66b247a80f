#version 450
#extension GL_GOOGLE_include_directive : require
// Probe irradiance and blend weight for every terrain vertex, once per change of probes: the
// draw then reads it as a vertex attribute, so probe lighting costs a frame almost nothing.
layout(local_size_x = 64) in;
#include "blocks/glsl.h"
#include "blocks/probes.h"
#include "sh.glsl"
#include "probes.glsl"

// Every volume's interpolation-error map (ProbeVolumeRecord.errorMap), -1 where no probe
// covered the point.
layout(set = TLX_SET_SUBSYSTEM, binding = 4, std430) readonly buffer Errors { float e[]; } errors;
layout(set = TLX_SET_SUBSYSTEM, binding = 5, std430) readonly buffer Vertices { float v[]; } vertices;  // pos, normal
// Per vertex: (probe irradiance, blend weight), then the diagnostics of the probe-validity and
// interpolation-error views: (moved
// share, or -1 where no probe lights the vertex; interpolation error × known; known: 1 where the
// error was measured; 1 = inside a volume with no probe to light it). The error is premultiplied
// so that the rasteriser's blend, divided by the blended `known`, stays the error near
// unmeasured vertices instead of fading towards 0.
layout(set = TLX_SET_SUBSYSTEM, binding = 6, std430) writeonly buffer ProbeLight { vec4 v[]; } probeLight;

// Bilinear over the map points around (x, z); uncovered points drop out. known = 0: no value.
float mapError(ProbeVolumeRecord vol, vec2 xz, out float known) {
    known = 0.0;
    ivec2 size = ivec2(vol.errorNx, vol.errorNz);
    if (size.x <= 0 || size.y <= 0) return 0.0;
    if (!(vol.errorStep > 0.0)) return 0.0;
    vec2 u = (xz - vec2(vol.errorX0, vol.errorZ0)) / vol.errorStep;
    // Beyond half a step outside the outermost points nothing was measured.
    if (any(lessThan(u, vec2(-0.5))) || any(greaterThan(u, vec2(size) - 0.5))) return 0.0;
    vec2 g = clamp(u, vec2(0.0), vec2(size - 1));
    ivec2 c0 = min(ivec2(floor(g)), size - 1);
    vec2 f = g - vec2(c0);
    float sum = 0.0, wsum = 0.0;
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        ivec2 c = min(c0 + o, size - 1);
        float e = errors.e[vol.firstError + c.x + c.y * size.x];
        vec2 wv = mix(vec2(1.0) - f, f, vec2(o));
        float w = wv.x * wv.y;
        if (e < 0.0 || w <= 0.0) continue;
        sum += w * e;
        wsum += w;
    }
    if (wsum <= 0.0) return 0.0;
    known = 1.0;
    return sum / wsum;
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uint(probeSet.vertexCount)) return;
    vec3 p = vec3(vertices.v[6 * i], vertices.v[6 * i + 1], vertices.v[6 * i + 2]);
    vec3 n = normalize(vec3(vertices.v[6 * i + 3], vertices.v[6 * i + 4], vertices.v[6 * i + 5]));
    float weight = 0.0, moved = 0.0, known = 0.0, error = 0.0;
    int volume = -1;
    bool unlit = false;
    vec3 irradiance = probeIrradiance(p, n, weight, moved, volume, unlit);
    if (volume >= 0 && probeSet.anyErrorMap == 1) error = mapError(volumes.v[volume], p.xz, known);
    probeLight.v[2 * i] = vec4(irradiance, weight);
    probeLight.v[2 * i + 1] = vec4(volume >= 0 ? moved : -1.0, error * known, known, unlit ? 1.0 : 0.0);
}
