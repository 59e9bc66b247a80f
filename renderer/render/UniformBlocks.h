#pragma once
// The C++ side of the uniform blocks in shaders/blocks/: each block file is expanded twice, once
// into a struct (glm members, 16-byte aligned like std140) and once into a static_assert that the
// struct's size is the block's std140 size. One definition, so C++ and GLSL cannot drift apart.

#include <cstdint>

#include <glm/mat4x4.hpp>
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
#include "blocks/all.h"  // expands the blocks, then undefines the TLX_ macros

}  // namespace terralux::blocks
