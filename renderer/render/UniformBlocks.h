#pragma once
// The C++ side of the uniform blocks in shaders/blocks/: each block file is expanded twice, once
// into a struct (glm members, 16-byte aligned like std140) and once into a static_assert that the
// struct's size is the block's std140 size. One definition, so C++ and GLSL cannot drift apart.

#include <cstdint>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "blocks/sets.h"

namespace terralux::blocks {

#define TLX_BLOCK_BEGIN(NAME, SET, BINDING)              \
    struct NAME {                                        \
        static constexpr uint32_t kSet = SET;            \
        static constexpr uint32_t kBinding = BINDING;    \
        static constexpr const char* kName = #NAME;
#define TLX_BLOCK_END(INSTANCE) };
#define TLX_STRUCT_BEGIN(NAME) struct NAME {
#define TLX_STRUCT_END };
#define TLX_VEC4(N) alignas(16) glm::vec4 N{0.0f};
#define TLX_IVEC4(N) alignas(16) glm::ivec4 N{0};
#define TLX_MAT4(N) alignas(16) glm::mat4 N{1.0f};
#define TLX_MAT4_ARRAY(N, COUNT) alignas(16) glm::mat4 N[COUNT]{};
#define TLX_VEC4_ARRAY(N, COUNT) alignas(16) glm::vec4 N[COUNT]{};
#define TLX_STRUCT_ARRAY(TYPE, N, COUNT) alignas(16) TYPE N[COUNT]{};
// One 16-byte row each: the row's first member starts it, the rest pack after it as std140 packs
// them, and the GLSL side's padding scalars are left to the alignment of the next row.
#define TLX_VEC3(V) alignas(16) glm::vec3 V{0.0f};
#define TLX_VEC3_FLOAT(V, F) alignas(16) glm::vec3 V{0.0f}; float F = 0.0f;
#define TLX_IVEC3_INT(V, I) alignas(16) glm::ivec3 V{0}; int32_t I = 0;
#define TLX_VEC2_VEC2(A, B) alignas(16) glm::vec2 A{0.0f}; glm::vec2 B{0.0f};
#define TLX_VEC2_FLOAT2(V, A, B) alignas(16) glm::vec2 V{0.0f}; float A = 0.0f; float B = 0.0f;
#define TLX_FLOAT1(A) alignas(16) float A = 0.0f;
#define TLX_FLOAT2(A, B) alignas(16) float A = 0.0f; float B = 0.0f;
#define TLX_FLOAT3(A, B, C) alignas(16) float A = 0.0f; float B = 0.0f; float C = 0.0f;
#define TLX_FLOAT4(A, B, C, D) alignas(16) float A = 0.0f; float B = 0.0f; float C = 0.0f; float D = 0.0f;
#define TLX_INT1(A) alignas(16) int32_t A = 0;
#define TLX_INT2(A, B) alignas(16) int32_t A = 0; int32_t B = 0;
#define TLX_INT3(A, B, C) alignas(16) int32_t A = 0; int32_t B = 0; int32_t C = 0;
#define TLX_INT4(A, B, C, D) alignas(16) int32_t A = 0; int32_t B = 0; int32_t C = 0; int32_t D = 0;
#include "blocks/all.h"  // expands the blocks, then undefines the TLX_ macros

// std140 sizes: every member kind used here is a multiple of 16 bytes.
#define TLX_BLOCK_BEGIN(NAME, SET, BINDING) static_assert(sizeof(NAME) == 0
#define TLX_BLOCK_END(INSTANCE) , "C++ struct differs from its std140 block");
#define TLX_STRUCT_BEGIN(NAME) static_assert(sizeof(NAME) == 0
#define TLX_STRUCT_END , "C++ struct differs from its std430 struct");
#define TLX_VEC4(N) + 16
#define TLX_IVEC4(N) + 16
#define TLX_MAT4(N) + 64
#define TLX_MAT4_ARRAY(N, COUNT) + 64 * (COUNT)
#define TLX_VEC4_ARRAY(N, COUNT) + 16 * (COUNT)
#define TLX_STRUCT_ARRAY(TYPE, N, COUNT) + sizeof(TYPE) * (COUNT)
#define TLX_VEC3(V) + 16
#define TLX_VEC3_FLOAT(V, F) + 16
#define TLX_IVEC3_INT(V, I) + 16
#define TLX_VEC2_VEC2(A, B) + 16
#define TLX_VEC2_FLOAT2(V, A, B) + 16
#define TLX_FLOAT1(A) + 16
#define TLX_FLOAT2(A, B) + 16
#define TLX_FLOAT3(A, B, C) + 16
#define TLX_FLOAT4(A, B, C, D) + 16
#define TLX_INT1(A) + 16
#define TLX_INT2(A, B) + 16
#define TLX_INT3(A, B, C) + 16
#define TLX_INT4(A, B, C, D) + 16
#include "blocks/all.h"  // expands the blocks, then undefines the TLX_ macros

}  // namespace terralux::blocks
