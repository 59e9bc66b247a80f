// Every uniform block and storage struct, in one list: C++ expands it once for the structs and
// once for their std140/std430 size checks (renderer/render/UniformBlocks.h), defining the TLX_
// macros before each inclusion; they are undefined here after it. A new subsystem's block is one
// more line here.
#include "blocks/camera.h"
#include "blocks/surface.h"
#include "blocks/sun_sky.h"
#include "blocks/atmosphere.h"
#include "blocks/shadows.h"
#include "blocks/probes.h"
#include "blocks/overlay.h"
#include "blocks/water.h"
#include "blocks/reflections.h"
#include "blocks/lpv.h"
#include "blocks/lpv_propagation.h"
#undef TLX_BLOCK_BEGIN
#undef TLX_BLOCK_END
#undef TLX_STRUCT_BEGIN
#undef TLX_STRUCT_END
#undef TLX_VEC4
#undef TLX_IVEC4
#undef TLX_MAT4
#undef TLX_MAT4_ARRAY
#undef TLX_VEC4_ARRAY
#undef TLX_STRUCT_ARRAY
#undef TLX_VEC3
#undef TLX_VEC3_FLOAT
#undef TLX_IVEC3_INT
#undef TLX_VEC2_VEC2
#undef TLX_VEC2_FLOAT2
#undef TLX_FLOAT1
#undef TLX_FLOAT2
#undef TLX_FLOAT3
#undef TLX_FLOAT4
#undef TLX_INT1
#undef TLX_INT2
#undef TLX_INT3
#undef TLX_INT4
