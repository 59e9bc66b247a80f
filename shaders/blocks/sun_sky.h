// Sun and sky (docs/lighting.md): the directional sun and the sky's radiance as SH.
TLX_BLOCK_BEGIN(SunSkyBlock, TLX_SET_LIGHTS, 0)
    TLX_VEC3_FLOAT(sunDirection, sunAngularRadius)  // toward the sun; radians
    TLX_VEC3(sunIlluminance)  // rgb
    TLX_VEC4_ARRAY(skySh, 9)  // sky radiance SH coefficient k in rgb (docs/formats.md convention)
TLX_BLOCK_END(sunSky)
