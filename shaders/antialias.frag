#version 450
// The picture views' anti-aliasing (docs/lighting.md, "Anti-aliasing"), one full-screen pass
// from the frame drawn into the output image:
//   kMode 0, fxaa: an edge filter on luminance after Lottes, "FXAA" (NVIDIA white paper, 2009):
//     a pixel whose 3x3 contrast is low is kept; otherwise the edge through it is classified
//     horizontal or vertical, followed both ways to its ends, and the pixel is resampled across
//     the edge by how far it lies from the nearer end (long, nearly straight edges get a smooth
//     ramp); thin features get a sub-pixel blend from the 3x3 average.
//   kMode 1, ssaa: the source holds 2x2 samples a pixel; their mean.
// kLinear 1: the source holds scene-linear values (EXR), whose luminance is compressed as a
// display would before edges are judged.
#extension GL_GOOGLE_include_directive : require
#include "display_math.glsl"

layout(constant_id = 0) const int kMode = 0;
layout(constant_id = 1) const int kLinear = 0;

layout(set = 0, binding = 0) uniform sampler2D source;

layout(location = 0) in vec2 ndc;
layout(location = 0) out vec4 outColor;

// Contrast below max(kThresholdMin, kThreshold * local maximum) is not an edge (Lottes'
// "quality" settings: 1/8 of the local range, 1/32 absolute).
const float kThreshold = 0.125;
const float kThresholdMin = 0.0312;
const float kSubpixel = 0.75;   // how much of the 3x3 average a one-pixel feature takes
const int kSearchSteps = 12;

float luma(vec3 c) {
    float l = rec709Luminance(max(c.r, 0.0), max(c.g, 0.0), max(c.b, 0.0));
    if (kLinear == 1) l = sqrt(l / (1.0 + l));  // Reinhard, then roughly the display's gamma
    return l;
}

ivec2 size;

vec3 texel(ivec2 p) { return texelFetch(source, clamp(p, ivec2(0), size - 1), 0).rgb; }
float lumaAt(ivec2 p) { return luma(texel(p)); }
// Bilinear read at a position in pixels (pixel centres at k + 0.5).
vec3 sampleAt(vec2 p) { return textureLod(source, p / vec2(size), 0.0).rgb; }

float searchStep(int i) { return i < 5 ? 1.0 : i == 5 ? 1.5 : i < 10 ? 2.0 : i == 10 ? 4.0 : 8.0; }

void main() {
    size = textureSize(source, 0);
    ivec2 p = ivec2(gl_FragCoord.xy);
    if (kMode == 1) {
        ivec2 s = 2 * p;
        vec4 sum = texelFetch(source, s, 0) + texelFetch(source, s + ivec2(1, 0), 0) +
                   texelFetch(source, s + ivec2(0, 1), 0) + texelFetch(source, s + ivec2(1, 1), 0);
        outColor = 0.25 * sum;
        return;
    }
    vec4 centre = texelFetch(source, p, 0);
    float m = luma(centre.rgb);
    float up = lumaAt(p + ivec2(0, -1)), down = lumaAt(p + ivec2(0, 1));
    float left = lumaAt(p + ivec2(-1, 0)), right = lumaAt(p + ivec2(1, 0));
    float hi = max(m, max(max(up, down), max(left, right)));
    float lo = min(m, min(min(up, down), min(left, right)));
    float range = hi - lo;
    if (range < max(kThresholdMin, hi * kThreshold)) {
        outColor = centre;
        return;
    }
    float ul = lumaAt(p + ivec2(-1, -1)), ur = lumaAt(p + ivec2(1, -1));
    float dl = lumaAt(p + ivec2(-1, 1)), dr = lumaAt(p + ivec2(1, 1));

    // Sub-pixel aliasing: how far the centre stands out of its neighbourhood's weighted mean.
    float mean = (2.0 * (up + down + left + right) + ul + ur + dl + dr) / 12.0;
    float sub = smoothstep(0.0, 1.0, clamp(abs(mean - m) / range, 0.0, 1.0));
    float subBlend = sub * sub * kSubpixel;

    // A horizontal edge changes most from row to row (second differences down the columns).
    float across = abs(ul + dl - 2.0 * left) + 2.0 * abs(up + down - 2.0 * m) + abs(ur + dr - 2.0 * right);
    float along = abs(ul + ur - 2.0 * up) + 2.0 * abs(left + right - 2.0 * m) + abs(dl + dr - 2.0 * down);
    bool horizontal = across >= along;
    float n1 = horizontal ? up : left, n2 = horizontal ? down : right;
    float g1 = n1 - m, g2 = n2 - m;
    bool towardFirst = abs(g1) >= abs(g2);
    float gradient = 0.25 * max(abs(g1), abs(g2));
    float sideMean = 0.5 * (m + (towardFirst ? n1 : n2));
    vec2 normal = horizontal ? vec2(0.0, towardFirst ? -1.0 : 1.0) : vec2(towardFirst ? -1.0 : 1.0, 0.0);
    vec2 tangent = horizontal ? vec2(1.0, 0.0) : vec2(0.0, 1.0);

    // Walk along the edge, half a pixel toward the steeper side, until the luminance there leaves
    // the edge's mean by a quarter of the gradient: the edge's ends.
    vec2 start = vec2(p) + 0.5 + 0.5 * normal;
    float end1 = 0.0, end2 = 0.0, d1 = 0.0, d2 = 0.0;
    bool done1 = false, done2 = false;
    for (int i = 0; i < kSearchSteps && !(done1 && done2); ++i) {
        float stepLength = searchStep(i);
        if (!done1) {
            d1 += stepLength;
            end1 = luma(sampleAt(start - d1 * tangent)) - sideMean;
            done1 = abs(end1) >= gradient;
        }
        if (!done2) {
            d2 += stepLength;
            end2 = luma(sampleAt(start + d2 * tangent)) - sideMean;
            done2 = abs(end2) >= gradient;
        }
    }
    bool nearerFirst = d1 < d2;
    float nearest = min(d1, d2);
    float offset = 0.5 - nearest / (d1 + d2);
    // Only where the luminance at the nearer end moves away from the centre's side does the edge
    // actually cross this pixel's side.
    bool centreBelow = m < sideMean;
    bool crosses = ((nearerFirst ? end1 : end2) < 0.0) != centreBelow;
    float shift = max(crosses ? offset : 0.0, subBlend);
    outColor = vec4(sampleAt(vec2(p) + 0.5 + shift * normal), centre.a);
}
