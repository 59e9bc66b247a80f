// The probe pass: how many volumes and vertices, and what the volumes carry.
TLX_BLOCK_BEGIN(ProbesBlock, TLX_SET_SUBSYSTEM, 0)
    TLX_INT3(volumeCount, vertexCount, anyErrorMap)  // volumes; terrain vertices; 1 = some
                                                     // volume has an interpolation-error map
TLX_BLOCK_END(probeSet)

// One volume of the probe pass's volume table (std430, the same layout as std140 here).
TLX_STRUCT_BEGIN(ProbeVolumeRecord)
    TLX_VEC3_FLOAT(origin, spacing)     // min corner; cell edge
    TLX_IVEC3_INT(dims, firstProbe)     // cells; first probe index in the coefficients
    TLX_INT2(firstCell, preConvolved)   // first cell in the cells; 1 = coefficients pre-convolved
    TLX_FLOAT2(fallbackBlend, shScale)  // fallback blend distance; SH scale
    TLX_INT3(firstError, errorNx, errorNz)      // first value in the error maps; its size (0: no map)
    TLX_FLOAT3(errorX0, errorZ0, errorStep)     // x, z of the map's point (0, 0); its step
TLX_STRUCT_END
