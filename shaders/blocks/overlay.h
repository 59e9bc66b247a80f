// The overlay pass: probe markers and octree leaves.
TLX_BLOCK_BEGIN(OverlayBlock, TLX_SET_SUBSYSTEM, 0)
    TLX_VEC4(leaves)     // x smallest leaf edge (metres), y smallest leaf drawn (pixels)
    TLX_IVEC4(markers)   // x 1 = draw valid probes, y 1 = draw moved and rejected probes
TLX_BLOCK_END(overlay)
