// Light propagation volumes and the local lights (docs/lighting.md, "Light propagation volumes"):
// the terrain pass's own set, bound only while the frame draws the LPV or the scene has point or
// spot lights. The volumes are storage buffers in Lpv.h's layout, read texel by texel so the
// shader blends exactly as Volumes::evaluate does.
TLX_STRUCT_BEGIN(LpvCascadeRecord)
    TLX_VEC3_FLOAT(minCorner, cellSize)  // metres
TLX_STRUCT_END
TLX_BLOCK_BEGIN(LpvBlock, TLX_SET_SUBSYSTEM, 0)
    TLX_INT4(cascadeCount, quality, coneSamples, lightCount)  // cascades (0: none bound); quality;
                          // cone-trace samples; local lights
    TLX_FLOAT4(indirectIntensity, fadeRange, addsToAmbient, viewExposure)  // indirect_intensity;
                          // fade range (cells); 1 = the LPV's light adds to the ambient
                          // (lighting.indirect lpv or both); the LPV views' exposure: 1 / cascade
                          // 0's light range (lpv::lightRange), 0 when it holds no light
    TLX_STRUCT_ARRAY(LpvCascadeRecord, cascades, 4)
TLX_BLOCK_END(lpv)

// One point or spot light (std430, the same layout as std140 here).
TLX_STRUCT_BEGIN(LocalLightRecord)
    TLX_VEC3_FLOAT(position, range)  // metres
    TLX_VEC3_FLOAT(emitted, spot)    // colour × intensity; 1 = spot
    TLX_VEC3(direction)              // unit cone axis (spot)
    TLX_FLOAT2(cosOuter, invConeWidth)  // cos outer angle; 1 / max(0.001, cos inner − cos outer)
TLX_STRUCT_END
#define TLX_LPV_LIGHT_BINDING 1     // storage: vec4 [cascade][channel R, G, B][cell], L1 SH intensity
#define TLX_LPV_GEOMETRY_BINDING 2  // storage: vec4 [cascade][corner], L1 SH blocking potential
#define TLX_LOCAL_LIGHTS_BINDING 3  // storage: LocalLightRecord per light
