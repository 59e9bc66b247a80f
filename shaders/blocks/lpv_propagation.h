// The LPV's propagation pass (lpv_propagate.comp; docs/lighting.md, "Light propagation volumes"):
// its own set. The faces are lpv::propagationNeighbours(), uploaded, so the pass steps through the
// CPU's values in the CPU's order.
TLX_BLOCK_BEGIN(LpvPropagationBlock, TLX_SET_SUBSYSTEM, 0)
    TLX_VEC4_ARRAY(neighbours, 6)  // xyz offset from source to destination cell, w its axis
    TLX_VEC4_ARRAY(faceDirs, 30)   // neighbour n's face f at 5n + f: xyz centre direction, w solid angle
    TLX_VEC4_ARRAY(faceLobes, 30)  // the same face's unit clamped-cosine lobe (L1 SH)
    TLX_FLOAT1(stepWeight)         // propagationStepWeight
    TLX_INT1(cascadeCount)
TLX_BLOCK_END(propagation)
#define TLX_LPV_WORK_BINDING 1      // storage: vec4 [region][cascade][channel][cell]; region 0 the
                                    // injected light, 1 and 2 alternate as the steps' output
#define TLX_LPV_SCALES_BINDING 2    // storage: float [2][cascade][channel][cell], the send scales
#define TLX_LPV_PROPAGATE_GEOMETRY_BINDING 3  // storage: the geometry volumes (as the terrain's set)
#define TLX_LPV_ACCUMULATED_BINDING 4         // storage: the light the terrain reads (its set's
                                              // TLX_LPV_LIGHT_BINDING buffer)
