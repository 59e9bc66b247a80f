// Shared by terrain.vert and terrain.frag: the frame uniforms and probe buffers (std140/std430),
// laid out to match renderer/TerrainRenderer.cpp.

layout(set = 0, binding = 0, std140) uniform Frame {
    mat4 viewProj;
    vec4 cameraPos;       // xyz
    vec4 sunDirection;    // xyz toward the sun
    vec4 sunIlluminance;  // rgb
    vec4 albedo;          // rgb
    vec4 skySh[9];        // sky radiance SH, rgb (FORMATS.md convention)
    ivec4 params;         // x debug view, y volume count, z probes enabled, w linear output
    vec4 exposure;        // x exposure, y roughness, zw viewport size in pixels
    vec4 overlay;         // x smallest octree-leaf edge of the leaf overlay, y 1 = probe overlay on
} frame;

struct Volume {
    vec4 originSpacing;   // xyz min corner, w cell edge
    ivec4 dimsProbe;      // xyz cells, w first probe index in probes[]
    ivec4 occupancy;      // x first cell in cells[], y 1 = coefficients are pre-convolved irradiance
    vec4 blend;           // x fallback blend distance, y SH scale
    ivec4 errorMap;       // x first value in the error buffer, y nx, z nz (0: no map)
    vec4 errorGrid;       // x, z of point (0, 0), step
};
// 9 per probe, RGB in xyz; coeffs[9 i].w = 1 when probe i was moved up out of the terrain.
layout(set = 0, binding = 1, std430) readonly buffer Probes { vec4 coeffs[]; } probes;
layout(set = 0, binding = 2, std430) readonly buffer Cells { int cell[]; } cells;
layout(set = 0, binding = 3, std430) readonly buffer Volumes { Volume v[]; } volumes;
