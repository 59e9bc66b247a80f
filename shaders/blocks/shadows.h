// Cascaded sun shadows (docs/lighting.md, "Shadows"): bound only by the shadowed terrain pipeline,
// with the cascades' depth maps (a 2D array, one layer per cascade) at the binding below.
TLX_BLOCK_BEGIN(ShadowBlock, TLX_SET_LIGHTS, 2)
    TLX_MAT4_ARRAY(lightViewProj, 4)  // world to each cascade's clip space
    TLX_VEC4(ends)        // per cascade: view depth (m) where it ends
    TLX_VEC4(texel)       // per cascade: metres per texel
    TLX_VEC4(depthRange)  // per cascade: metres from z = 0 to z = 1, along the light
    TLX_VEC3_FLOAT(forward, nearDepth)  // camera forward (view depth = dot(p − eye, forward));
                                        // near view depth
    TLX_FLOAT4(depthBias, normalBias, tanSunRadius, mapResolution)  // depth bias; normal bias
                          // (texels); tan(sun angular radius); map resolution (texels)
    TLX_INT4(cascadeCount, filterMode, horizonFrom, horizonWidth)  // cascades; 0 pcss, 1 pcf,
                          // 2 hard; the first cascade the terrain's horizon map stands in for
                          // (cascadeCount: none); the map's vertices a row
    TLX_INT1(horizonHeight)  // the horizon map's rows
    TLX_FLOAT2(cascadeBlend, fadeOut)  // share of each slice's depth over which it hands over to
                          // the next; 1 where terrain lies beyond the last cascade, which then
                          // fades to the unshadowed sun over the same share
TLX_BLOCK_END(shadow)
#define TLX_SHADOW_MAP_DEPTH_BINDING 3  // sampler2DArray: the stored depths, gathered and compared
#define TLX_SUN_HORIZON_BINDING 4  // storage buffer: the sun's visible share at each vertex of the
                                   // horizon map, one byte each (0..255), rows north to south
