// The probe pass: how many volumes and vertices, and what the volumes carry.
TLX_BLOCK_BEGIN(ProbesBlock, TLX_SET_SUBSYSTEM, 0)
    TLX_IVEC4(counts)    // x volumes, y terrain vertices
    TLX_IVEC4(flags)     // x 1 = some volume has an interpolation-error map
TLX_BLOCK_END(probeSet)

// One volume of the probe pass's volume table (std430, the same layout as std140 here).
TLX_STRUCT_BEGIN(ProbeVolumeRecord)
    TLX_VEC4(originSpacing)  // xyz min corner, w cell edge
    TLX_IVEC4(dimsProbe)     // xyz cells, w first probe index in the coefficients
    TLX_IVEC4(occupancy)     // x first cell in the cells, y 1 = coefficients are pre-convolved
    TLX_VEC4(blend)          // x fallback blend distance, y SH scale
    TLX_IVEC4(errorMap)      // x first value in the error maps, y nx, z nz (0: no map)
    TLX_VEC4(errorGrid)      // x, z of point (0, 0), step
TLX_STRUCT_END
