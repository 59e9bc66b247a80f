// GLSL expansion of the uniform-block definitions in this folder (C++: renderer/render/
// UniformBlocks.h). Include once per shader, before the blocks it binds.
#include "sets.h"
#define TLX_BLOCK_BEGIN(NAME, SET, BINDING) layout(set = SET, binding = BINDING, std140) uniform NAME {
#define TLX_BLOCK_END(INSTANCE) } INSTANCE;
#define TLX_STRUCT_BEGIN(NAME) struct NAME {
#define TLX_STRUCT_END };
#define TLX_VEC4(N) vec4 N;
#define TLX_IVEC4(N) ivec4 N;
#define TLX_MAT4(N) mat4 N;
#define TLX_MAT4_ARRAY(N, COUNT) mat4 N[COUNT];
#define TLX_VEC4_ARRAY(N, COUNT) vec4 N[COUNT];
