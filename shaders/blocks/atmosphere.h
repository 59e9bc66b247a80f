// Height fog (docs/lighting.md, "Height fog"): read by the terrain and sky passes when the scene
// has fog (a specialisation constant removes the code otherwise).
TLX_BLOCK_BEGIN(AtmosphereBlock, TLX_SET_LIGHTS, 1)
    TLX_VEC4(fog)        // x density (1/m at the base), y height falloff (1/m), z base height (m),
                         // w Henyey–Greenstein anisotropy
    TLX_VEC4(fogColor)   // rgb ambient inscatter radiance, w sun inscatter scale
TLX_BLOCK_END(atmosphere)
