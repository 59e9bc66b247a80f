// Height fog (docs/lighting.md, "Height fog"): read by the terrain and sky passes when the scene
// has fog (a specialisation constant removes the code otherwise).
TLX_BLOCK_BEGIN(AtmosphereBlock, TLX_SET_LIGHTS, 1)
    TLX_FLOAT4(fogDensity, fogFalloff, fogBase, fogAnisotropy)  // 1/m at the base; height falloff
                         // (1/m); base height (m); Henyey–Greenstein anisotropy
    TLX_VEC3_FLOAT(fogColor, sunInscatter)  // ambient inscatter radiance; sun inscatter scale
TLX_BLOCK_END(atmosphere)
