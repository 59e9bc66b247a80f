// Cascaded sun shadows (docs/lighting.md, "Shadows"): bound only by the shadowed terrain pipeline,
// with the cascades' depth maps (a 2D array, one layer per cascade) at the two bindings below.
TLX_BLOCK_BEGIN(ShadowBlock, TLX_SET_LIGHTS, 2)
    TLX_MAT4_ARRAY(lightViewProj, 4)  // world to each cascade's clip space
    TLX_VEC4(ends)        // view depth (m) where each cascade ends
    TLX_VEC4(texel)       // metres per texel of each cascade
    TLX_VEC4(depthRange)  // metres from z = 0 to z = 1 of each cascade, along the light
    TLX_VEC4(forward)     // xyz camera forward (view depth = dot(p − eye, forward)), w near view depth
    TLX_VEC4(bias)        // x depth bias, y normal bias (texels), z tan(sun angular radius),
                          // w map resolution (texels)
    TLX_IVEC4(mode)       // x cascades, y filter: 0 pcss, 1 pcf, 2 hard
TLX_BLOCK_END(shadow)
#define TLX_SHADOW_MAP_COMPARE_BINDING 3  // sampler2DArrayShadow (depth compare)
#define TLX_SHADOW_MAP_DEPTH_BINDING 4    // sampler2DArray (the stored depths: blocker search)
