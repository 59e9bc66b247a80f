#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
// The LPV's propagation on the GPU: lpv::propagationStep and Volumes::propagate's accumulation,
// the same operations in the same order (renderer/lpv/Lpv.cpp; Kaplanyan & Dachsbacher 2010, Sec. 5). One invocation a
// cell of every cascade:
//   pass 0 (once, before the first step): each injected cell's send scale per channel, the factor
//           that makes its non-negative face fluxes sum to its flux (Lpv.cpp sendScales());
//   pass 1 (a dispatch a step): each destination cell gathers what its six neighbours send
//           through their thirty faces, blocked by the geometry on the shared face from the second
//           step on, writes it as the step's output, adds it to the accumulated light (the first
//           step to the injected) and, but for the last step, computes its own send scales for
//           the next.
// The loops over channels and send-scale faces are unrolled, so the channels' sums stay in
// registers.
layout(local_size_x = 256) in;
#include "blocks/glsl.h"
#include "blocks/lpv_propagation.h"
#include "sh_basis.glsl"

layout(set = TLX_SET_SUBSYSTEM, binding = TLX_LPV_WORK_BINDING, std430) buffer Work { vec4 v[]; } work;
layout(set = TLX_SET_SUBSYSTEM, binding = TLX_LPV_SCALES_BINDING, std430) buffer Scales { float v[]; } scales;
layout(set = TLX_SET_SUBSYSTEM, binding = TLX_LPV_PROPAGATE_GEOMETRY_BINDING, std430) readonly buffer Geometry { vec4 v[]; } geometry;
layout(set = TLX_SET_SUBSYSTEM, binding = TLX_LPV_ACCUMULATED_BINDING, std430) buffer Light { vec4 v[]; } light;
// x pass (0 the source's send scales, 1 gather), y source region, z destination region (pass 1),
// w 1 = the gather also writes the destination's send scales for the next step. Region 0 as the
// source is the first step: no occlusion (the injected surfels sit half a cell above their own
// surfaces) and the accumulation starts from the injected light.
layout(push_constant) uniform Push { ivec4 p; } push;

const int kGrid = 32;
const int kCorners = 33;
const int kCells = kGrid * kGrid * kGrid;
const float kTwoSqrtPi = 3.5449077018110318;

float shEvaluate(vec4 sh, vec3 d) { return sh.x * kShY00 + kShY1 * (sh.y * d.y + sh.z * d.z + sh.w * d.x); }

int cascades() { return int(propagation.cascadeCount); }
int regionBase(int region) { return region * cascades() * 3 * kCells; }
int lightIndex(int cascade, int channel, int cell) { return (cascade * 3 + channel) * kCells + cell; }
int cellIndex(ivec3 c) { return c.x + kGrid * (c.y + kGrid * c.z); }
bool inside(ivec3 c) { return all(greaterThanEqual(c, ivec3(0))) && all(lessThan(c, ivec3(kGrid))); }

// Lpv.cpp faceGeometry(): the mean of the four corner texels of the face between source s and its
// neighbour along n.
vec4 faceGeometry(int cascade, ivec3 s, int n) {
    ivec3 offset = ivec3(propagation.neighbours[n].xyz);
    int axis = int(propagation.neighbours[n].w);
    ivec3 base = s;
    if (offset[axis] > 0) base[axis] += 1;
    int o1 = (axis + 1) % 3, o2 = (axis + 2) % 3;
    vec4 sum = vec4(0.0);
    [[unroll]] for (int i = 0; i < 2; ++i)
        [[unroll]] for (int j = 0; j < 2; ++j) {
            ivec3 c = base;
            c[o1] += i;
            c[o2] += j;
            sum += 0.25 * geometry.v[cascade * kCorners * kCorners * kCorners + c.x + kCorners * (c.y + kCorners * c.z)];
        }
    return sum;
}

// The factor that makes the non-negative face fluxes of a cell holding `sh` sum to its flux.
float sendScale(vec4 sh) {
    float flux = kTwoSqrtPi * sh.x;
    if (!(flux > 0.0)) return 0.0;
    float positive = 0.0;
    [[unroll]] for (int f = 0; f < 30; ++f)
        positive += max(0.0, shEvaluate(sh, propagation.faceDirs[f].xyz)) * propagation.faceDirs[f].w;
    return positive > 0.0 ? flux / positive : 0.0;
}

// The scales of region r's light live in half r % 2 of the scales buffer: a step reads its
// source's half and writes its destination's, the other.
int scalesBase(int region) { return (region % 2) * cascades() * 3 * kCells; }

void sendScales(int cascade, int cell) {
    int source = regionBase(push.p.y), base = scalesBase(push.p.y);
    [[unroll]] for (int ch = 0; ch < 3; ++ch) {
        int i = lightIndex(cascade, ch, cell);
        scales.v[base + i] = sendScale(work.v[source + i]);
    }
}

void gather(int cascade, int cell) {
    int source = regionBase(push.p.y), destination = regionBase(push.p.z);
    bool first = push.p.y == 0;
    float weight = propagation.stepWeight;
    ivec3 t = ivec3(cell % kGrid, (cell / kGrid) % kGrid, cell / (kGrid * kGrid));
    vec4 sum[3] = vec4[3](vec4(0.0), vec4(0.0), vec4(0.0));
    for (int n = 0; n < 6; ++n) {
        ivec3 s = t - ivec3(propagation.neighbours[n].xyz);
        if (!inside(s)) continue;
        int sc = cellIndex(s);
        vec4 g = first ? vec4(0.0) : faceGeometry(cascade, s, n);
        // The source's light and scales, read once for its five faces.
        vec4 sh[3];
        float scale[3];
        [[unroll]] for (int ch = 0; ch < 3; ++ch) {
            int i = lightIndex(cascade, ch, sc);
            sh[ch] = work.v[source + i];
            scale[ch] = scales.v[scalesBase(push.p.y) + i];
        }
        for (int k = 0; k < 5; ++k) {
            vec4 face = propagation.faceDirs[5 * n + k];
            vec4 lobe = propagation.faceLobes[5 * n + k];
            float transmit = first ? 1.0 : 1.0 - clamp(shEvaluate(g, -face.xyz), 0.0, 1.0);
            // A cell that sends nothing has scale 0 and adds zeros, as the CPU's skipping it does.
            [[unroll]] for (int ch = 0; ch < 3; ++ch) {
                float flux = scale[ch] * max(0.0, shEvaluate(sh[ch], face.xyz)) * face.w * weight * transmit;
                sum[ch] += flux * lobe;
            }
        }
    }
    [[unroll]] for (int ch = 0; ch < 3; ++ch) {
        int i = lightIndex(cascade, ch, cell);
        work.v[destination + i] = sum[ch];
        light.v[i] = (first ? work.v[i] : light.v[i]) + sum[ch];
        if (push.p.w != 0) scales.v[scalesBase(push.p.z) + i] = sendScale(sum[ch]);
    }
}

void main() {
    int id = int(gl_GlobalInvocationID.x);
    if (id >= cascades() * kCells) return;
    int cascade = id / kCells, cell = id % kCells;
    if (push.p.x == 0) sendScales(cascade, cell);
    else gather(cascade, cell);
}
