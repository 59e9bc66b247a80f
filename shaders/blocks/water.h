// The water plane (docs/lighting.md, "Water"): the water pass's own set. The reflection, the
// copy of the frame under the water and the bed/shore field are bound beside the block.
#include "blocks/limits.h"
// One Gerstner wave (water::WaveTerms).
TLX_STRUCT_BEGIN(WaveRecord)
    TLX_VEC2_FLOAT2(direction, k, amplitude)  // unit travel direction (x, z); rad/m; metres
    TLX_FLOAT2(omegaDeep, phase)              // deep-water ω (rad/s); phase (rad)
TLX_STRUCT_END
TLX_BLOCK_BEGIN(WaterBlock, TLX_SET_SUBSYSTEM, 0)
    TLX_FLOAT4(level, time, shoreFade, depthAware)  // engine y; seconds; shore fade distance (m);
                                                    // 1 = depth-aware dispersion
    TLX_VEC3_FLOAT(scatter, roughness)         // deep-water scatter albedo; GGX roughness
    TLX_VEC3_FLOAT(absorption, planarReflection)  // extinction per metre; 1 = planar reflection
                                                  // (0: the sky's)
    TLX_VEC2_FLOAT2(fieldSize, distortion, waveCount)  // bed/shore field (texels); reflection
                                                       // distortion per unit slope; waves used
    TLX_FLOAT1(meshSpacing)                    // metres between the water mesh's vertices
    TLX_STRUCT_ARRAY(WaveRecord, waves, TLX_MAX_WAVES)
TLX_BLOCK_END(water)
#define TLX_WATER_REFLECTION_BINDING 1  // sampler2D: the planar reflection, scene-linear
#define TLX_WATER_SCENE_BINDING 2       // sampler2D: the frame before the water, as the target holds it
#define TLX_WATER_FIELD_BINDING 3       // sampler2D: x depth of the bed below the level (m, negative on land), y distance to shore (m)
