// The limits the blocks are sized by, shared by C++ (the scene's rules, the packing) and GLSL
// (the shaders' loops): one number each.
#ifndef TLX_BLOCKS_LIMITS_H
#define TLX_BLOCKS_LIMITS_H
#define TLX_MAX_WAVES 8  // Gerstner waves on the water (water.waves)
#endif
