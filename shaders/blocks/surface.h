// Surface and material of the terrain, and the exposure that maps its light to the display. The
// surface maps (renderer/terrain/SurfaceMaps.h) are bound beside the block, at the bindings below.
TLX_BLOCK_BEGIN(SurfaceBlock, TLX_SET_VIEW, 1)
    TLX_VEC3_FLOAT(albedo, albedoFromMap)  // the constant albedo; 1 = the albedo map holds it instead
    TLX_FLOAT4(roughness, exposure, specularAA, roughnessFloor)  // GGX roughness; exposure;
                         // 1 = widen roughness by the normal variance; the roughness floor
    TLX_VEC2_VEC2(footprintMin, invFootprintSpan)  // the footprint's least (x, z); 1 / its extent
                                                   // (0 for one vertex)
    TLX_VEC2_VEC2(normalAoMapSize, albedoMapSize)  // texels, level 0
    TLX_FLOAT3(aoOnSky, aoOnProbes, probeAoLevel)  // 1 = AO darkens the sky light; its strength on
                         // probe light; the normal-AO mip level as coarse as the probes (<= 0:
                         // probes are as fine)
    TLX_FLOAT4(detailStrength, detailScale, detailFade, albedoVariation)  // detail normal strength
                         // (0 off); metres per repeat; fade distance (m); albedo variation (±, 0 off)
    TLX_VEC3_FLOAT(groundAlbedo, groundHeight)  // the skirt as the sky pass draws it: the border's
                         // mean linear albedo and mean height (engine space)
    TLX_FLOAT3(ground, skyImage, skyImageLod)  // 1 = the skirt is on: below the horizon the sky
                         // pass draws the ground; 1 = the sky pass draws the sky image (hdr,
                         // physical), not the SH; the image's mip level a pixel covers
    TLX_VEC3_FLOAT(skyImageScale, skyImageRotation)  // the image's radiance factor (intensity ×
                         // tint); its rotation about +Y in turns (sky_math.glsl)
TLX_BLOCK_END(surface)
#define TLX_SURFACE_NORMAL_AO_BINDING 2  // sampler2D: xyz mean normal, w sky visibility, mipped
#define TLX_SURFACE_ALBEDO_BINDING 3     // sampler2D: linear albedo (sRGB texels), mipped
#define TLX_SURFACE_FILLED_BINDING 4     // sampler2D: share of filled nodata cells
#define TLX_SKY_IMAGE_BINDING 5          // sampler2D: the sky's equirectangular radiance, level 0
