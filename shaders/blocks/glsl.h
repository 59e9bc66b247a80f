// GLSL expansion of the uniform-block definitions in this folder (C++: renderer/render/
// UniformBlocks.h). Include once per shader, before the blocks it binds.
//
// Every member macro below is one 16-byte row, so std140 (and std430) place each row at the
// next multiple of 16 exactly as the C++ structs' alignas(16) does; a row's unused scalars are
// padding named after its first field.
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
#define TLX_STRUCT_ARRAY(TYPE, N, COUNT) TYPE N[COUNT];
#define TLX_VEC3(V) vec3 V; float V##Pad_;
#define TLX_VEC3_FLOAT(V, F) vec3 V; float F;
#define TLX_IVEC3_INT(V, I) ivec3 V; int I;
#define TLX_VEC2_VEC2(A, B) vec2 A; vec2 B;
#define TLX_VEC2_FLOAT2(V, A, B) vec2 V; float A; float B;
#define TLX_FLOAT1(A) float A; float A##Pad1_; float A##Pad2_; float A##Pad3_;
#define TLX_FLOAT2(A, B) float A; float B; float A##Pad2_; float A##Pad3_;
#define TLX_FLOAT3(A, B, C) float A; float B; float C; float A##Pad3_;
#define TLX_FLOAT4(A, B, C, D) float A; float B; float C; float D;
#define TLX_INT1(A) int A; int A##Pad1_; int A##Pad2_; int A##Pad3_;
#define TLX_INT2(A, B) int A; int B; int A##Pad2_; int A##Pad3_;
#define TLX_INT3(A, B, C) int A; int B; int C; int A##Pad3_;
#define TLX_INT4(A, B, C, D) int A; int B; int C; int D;
