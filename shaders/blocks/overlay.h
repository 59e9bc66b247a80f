// The overlay pass: probe markers and octree leaves.
TLX_BLOCK_BEGIN(OverlayBlock, TLX_SET_SUBSYSTEM, 0)
    // Smallest leaf edge (m); smallest leaf drawn and a marker's half width (pixels of the drawn
    // frame: twice the output's under ssaa, so both look the same size on screen).
    TLX_FLOAT3(smallestLeaf, smallestLeafPixels, markerPixels)
    TLX_INT2(drawValid, drawMovedRejected)  // 1 = draw valid probes; 1 = draw moved and rejected
TLX_BLOCK_END(overlay)
