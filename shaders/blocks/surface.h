// Surface and material of the terrain, and the exposure that maps its light to the display. The
// surface maps (renderer/terrain/SurfaceMaps.h) are bound beside the block, at the bindings below.
TLX_BLOCK_BEGIN(SurfaceBlock, TLX_SET_VIEW, 1)
    TLX_VEC4(albedo)     // rgb the constant albedo; w 1 = the albedo map holds the albedo instead
    TLX_VEC4(material)   // x GGX roughness, y exposure, z 1 = widen roughness by the normal
                         // variance, w the roughness floor
    TLX_VEC4(footprint)  // xy the footprint's least (x, z), zw 1 / its extent (0 for one vertex)
    TLX_VEC4(mapSizes)   // xy normal-AO map size, zw albedo map size (texels, level 0)
    TLX_VEC4(ao)         // x 1 = AO darkens the sky light, y its strength on probe light, z the
                         // normal-AO mip level as coarse as the probes (<= 0: probes are as fine)
    TLX_VEC4(detail)     // x detail normal strength (0 off), y metres per repeat, z fade distance
                         // (m), w albedo variation (±, 0 off)
TLX_BLOCK_END(surface)
#define TLX_SURFACE_NORMAL_AO_BINDING 2  // sampler2D: xyz mean normal, w sky visibility, mipped
#define TLX_SURFACE_ALBEDO_BINDING 3     // sampler2D: linear albedo (sRGB texels), mipped
#define TLX_SURFACE_FILLED_BINDING 4     // sampler2D: share of filled nodata cells
