// The overlay pass: probe markers and octree leaves.
TLX_BLOCK_BEGIN(OverlayBlock, TLX_SET_SUBSYSTEM, 0)
    TLX_FLOAT2(smallestLeaf, smallestLeafPixels)  // smallest leaf edge (m); smallest leaf drawn (px)
    TLX_INT2(drawValid, drawMovedRejected)  // 1 = draw valid probes; 1 = draw moved and rejected
TLX_BLOCK_END(overlay)
