// Reflection probes (docs/lighting.md, "Reflection probes in the renderer"): bound in the lights
// set only while a probe set is, by the pipelines built with TLX_REFLECTIONS. The grid is a
// uniform block (it carries the live strength, so it is per frame); the probes are a storage
// buffer of records and, for the cubemap encoding, a cube-map array of their cubes beside it.
TLX_BLOCK_BEGIN(ReflectionBlock, TLX_SET_LIGHTS, 5)
    TLX_INT4(nx, nz, encoding, mipLevels)  // probes along x and z; 0 faces, 1 cubemap; mips
    TLX_VEC2_VEC2(origin, spacing)         // (x, z) of probe 0; spacing (x, z), 0 on a one-probe axis
    TLX_VEC2_FLOAT2(cellSize, blendDistance, strength)  // cell (x, z); fallback blend distance (m);
                                                        // strength
TLX_BLOCK_END(reflection)

// One probe of the set (std430, the same layout as std140 here).
TLX_STRUCT_BEGIN(ReflectionProbeRecord)
    TLX_VEC3(position)    // capture point: the box's centre
    TLX_VEC3(halfExtent)  // the box's half extents
    TLX_VEC4_ARRAY(faces, 6)  // rgb mean radiance of each face, +X, −X, +Y, −Y, +Z, −Z
TLX_STRUCT_END
#define TLX_REFLECTION_PROBES_BINDING 6  // storage buffer: ReflectionProbeRecord per probe
#define TLX_REFLECTION_CUBES_BINDING 7   // samplerCubeArray: cube = probe, mip m at roughness m/(mips − 1)
