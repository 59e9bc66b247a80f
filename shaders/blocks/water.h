// The water plane (docs/lighting.md, "Water"): the water pass's own set. The reflection, the
// copy of the frame under the water and the bed/shore field are bound beside the block.
#include "blocks/limits.h"
TLX_BLOCK_BEGIN(WaterBlock, TLX_SET_SUBSYSTEM, 0)
    TLX_VEC4(plane)        // x level (engine y), y time (s), z shore fade distance (m), w 1 = depth-aware dispersion
    TLX_VEC4(scatter)      // rgb deep-water scatter albedo, w GGX roughness
    TLX_VEC4(absorption)   // rgb extinction per metre, w 1 = planar reflection (0: the sky's)
    TLX_VEC4(look)         // x reflection distortion per unit slope, y wave count, zw field size (texels)
    TLX_VEC4(mesh)         // x metres between the water mesh's vertices
    TLX_VEC4_ARRAY(waves, TLX_MAX_WAVES)   // per wave: xy unit travel direction (x, z), z k (rad/m), w amplitude (m)
    TLX_VEC4_ARRAY(phases, TLX_MAX_WAVES)  // per wave: x deep-water ω (rad/s), y phase (rad)
TLX_BLOCK_END(water)
#define TLX_WATER_REFLECTION_BINDING 1  // sampler2D: the planar reflection, scene-linear
#define TLX_WATER_SCENE_BINDING 2       // sampler2D: the frame before the water, as the target holds it
#define TLX_WATER_FIELD_BINDING 3       // sampler2D: x depth of the bed below the level (m, negative on land), y distance to shore (m)
