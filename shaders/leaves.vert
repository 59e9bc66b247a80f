#version 450
#extension GL_GOOGLE_include_directive : require
// Octree-leaf overlay: the 12 edges of each leaf box as a line list (24 vertices per instance),
// bright for the smallest leaves and darker for each doubling of the edge.
#include "blocks/glsl.h"
#include "blocks/camera.h"
#include "blocks/overlay.h"

layout(location = 0) in vec4 inLeaf;  // xyz min corner, w edge
layout(location = 0) out vec3 color;

void main() {
    // Edge k runs from corner a to corner b; corners are bit patterns (x, y, z).
    const int ends[24] = int[](0, 1, 2, 3, 4, 5, 6, 7,   // along x
                               0, 2, 1, 3, 4, 6, 5, 7,   // along y
                               0, 4, 1, 5, 2, 6, 3, 7);  // along z
    int corner = ends[gl_VertexIndex % 24];
    vec3 offset = vec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
    gl_Position = camera.viewProj * vec4(inLeaf.xyz + inLeaf.w * offset, 1.0);
    // Level of detail: a leaf narrower than overlay.smallestLeafPixels pixels on screen is left out, so a whole terrain
    // shows its coarse leaves and zooming in reveals the fine ones.
    vec3 centre = inLeaf.xyz + 0.5 * inLeaf.w;
    vec4 c = camera.viewProj * vec4(centre, 1.0);
    vec4 cx = camera.viewProj * vec4(centre + vec3(inLeaf.w, 0.0, 0.0), 1.0);
    vec4 cz = camera.viewProj * vec4(centre + vec3(0.0, 0.0, inLeaf.w), 1.0);
    if (c.w > 0.0 && cx.w > 0.0 && cz.w > 0.0) {
        vec2 halfSize = 0.5 * camera.viewportSize;
        vec2 p = c.xy / c.w * halfSize;
        float pixels = max(length(cx.xy / cx.w * halfSize - p), length(cz.xy / cz.w * halfSize - p));
        if (pixels < overlay.smallestLeafPixels) gl_Position = vec4(0.0, 0.0, 2.0, 1.0);  // outside the depth range: clipped
    }
    float level = log2(max(inLeaf.w / max(overlay.smallestLeaf, 1e-6), 1.0));
    color = mix(vec3(1.0, 0.95, 0.6), vec3(0.35, 0.25, 0.9), clamp(level / 5.0, 0.0, 1.0));
}
