// Descriptor-set numbers, shared by C++ and GLSL. A pipeline binds only the sets of the
// subsystems its scene uses; a set it does not use is an empty layout.
//   0 view: what every pass of a frame sees (camera and frame, surface)
//   1 lights: sun and sky, height fog, the sun's shadow cascades, reflection probes
//   2 the pass's own subsystem: probes for the probe pass, overlays for the overlay pass (and
//     water, fog, LPV, post as they come)
#define TLX_SET_VIEW 0
#define TLX_SET_LIGHTS 1
#define TLX_SET_SUBSYSTEM 2
