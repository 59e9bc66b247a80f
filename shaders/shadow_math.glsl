// Which shadow a cascade's slice takes, written in the common subset of GLSL and C++ so the
// shaders and the CPU (the renderer's hand-over, the exporter, tests) use the same rule
// (docs/lighting.md, "Shadows"). C++ includes it through shaders/ShaderMath.h.
#ifndef TLX_SHADOW_MATH_GLSL
#define TLX_SHADOW_MATH_GLSL
#ifndef TLX_SHARED
#define TLX_SHARED
#endif

// Depth allowed below the receiver's plane, in texels of its slope: a neighbouring triangle in a
// valley rises above the plane through the point. ½ texel left 0.66 % acne on the committed crops
// at a 5° sun, one texel lost more of the traced shadows.
TLX_SHARED float shadowSlopeTexels() { return 0.75f; }

// The ground length of the shortest shadow a cascade of `texel` metres still draws at a sun
// `tanElevation` high: the allowance above lets a blocker less than shadowSlopeTexels() texels of
// the receiver plane's slope in front of it pass, and on level ground that slope is 1/tan(e)
// metres of depth per metre across the map, so shadows shorter than this on the ground are lost.
TLX_SHARED float shadowShortestDrawn(float texel, float tanElevation) {
    return shadowSlopeTexels() * texel / max(tanElevation, 1.0e-6f);
}

// Whether a cascade hands the terrain's own shadow to its horizon map (one sample per DEM
// vertex, `cell` metres apart): where the map loses shadows longer than the DEM's cell, the
// relief the DEM resolves casts shadows the map cannot draw.
TLX_SHARED bool shadowTakesHorizon(float texel, float tanElevation, float cell) {
    return shadowShortestDrawn(texel, tanElevation) > cell;
}

#endif
