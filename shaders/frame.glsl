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
    vec4 exposure;        // x exposure, y roughness
} frame;

struct Volume {
    vec4 originSpacing;   // xyz min corner, w cell edge
    ivec4 dimsProbe;      // xyz cells, w first probe index in probes[]
    ivec4 occupancy;      // x first cell in cells[], y 1 = coefficients are pre-convolved irradiance
    vec4 blend;           // x fallback blend distance, y SH scale
};
layout(set = 0, binding = 1, std430) readonly buffer Probes { vec4 coeffs[]; } probes;  // 9 per probe
layout(set = 0, binding = 2, std430) readonly buffer Cells { int cell[]; } cells;
layout(set = 0, binding = 3, std430) readonly buffer Volumes { Volume v[]; } volumes;
