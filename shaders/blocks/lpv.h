// Light propagation volumes and the local lights (docs/lighting.md, "Light propagation volumes"):
// the terrain pass's own set, bound only while the frame draws the LPV or the scene has point or
// spot lights. The volumes are storage buffers in Lpv.h's layout, read texel by texel so the
// shader blends exactly as Volumes::evaluate does.
TLX_BLOCK_BEGIN(LpvBlock, TLX_SET_SUBSYSTEM, 0)
    TLX_IVEC4(counts)     // x cascades (0: none bound), y quality, z cone-trace samples, w local lights
    TLX_VEC4(params)      // x indirect_intensity, y fade range (cells), z 1 = the LPV's light adds to
                          // the ambient (lighting.indirect lpv or both), w the LPV views' exposure:
                          // 1 / cascade 0's light range (lpv::lightRange), 0 when it holds no light
    TLX_VEC4_ARRAY(cascades, 4)  // per cascade: xyz min corner (m), w cell size (m)
TLX_BLOCK_END(lpv)

// One point or spot light (std430, the same layout as std140 here).
TLX_STRUCT_BEGIN(LocalLightRecord)
    TLX_VEC4(positionRange)  // xyz position (m), w range (m)
    TLX_VEC4(emitted)        // rgb colour × intensity, w 1 = spot
    TLX_VEC4(direction)      // xyz unit cone axis (spot)
    TLX_VEC4(cone)           // x cos outer angle, y 1 / max(0.001, cos inner − cos outer)
TLX_STRUCT_END
#define TLX_LPV_LIGHT_BINDING 1     // storage: vec4 [cascade][channel R, G, B][cell], L1 SH intensity
#define TLX_LPV_GEOMETRY_BINDING 2  // storage: vec4 [cascade][corner], L1 SH blocking potential
#define TLX_LOCAL_LIGHTS_BINDING 3  // storage: LocalLightRecord per light
