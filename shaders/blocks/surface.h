// Surface and material of the terrain, and the exposure that maps its light to the display.
TLX_BLOCK_BEGIN(SurfaceBlock, TLX_SET_VIEW, 1)
    TLX_VEC4(albedo)     // rgb
    TLX_VEC4(material)   // x GGX roughness, y exposure
TLX_BLOCK_END(surface)
