// Sun and sky (docs/lighting.md): the directional sun and the sky's radiance as SH.
TLX_BLOCK_BEGIN(SunSkyBlock, TLX_SET_LIGHTS, 0)
    TLX_VEC4(sunDirection)    // xyz toward the sun, w angular radius (radians)
    TLX_VEC4(sunIlluminance)  // rgb
    TLX_VEC4_ARRAY(skySh, 9)  // sky radiance SH, rgb (docs/formats.md convention)
TLX_BLOCK_END(sunSky)
