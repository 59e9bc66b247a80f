// Camera and frame: what every pass of a frame sees.
TLX_BLOCK_BEGIN(CameraBlock, TLX_SET_VIEW, 0)
    TLX_MAT4(viewProj)   // Vulkan clip space
    TLX_MAT4(invViewProj)  // clip space back to world (the sky pass's view rays)
    TLX_VEC4(position)   // xyz camera position, w far plane distance (metres)
    TLX_VEC4(viewport)   // xy size in pixels, zw 1 / size
    TLX_IVEC4(view)      // x debug view, y 1 = scene-linear output (EXR), z what the per-vertex
                         // attribute holds: 0 probe light, 1 the probe diagnostics, 2 the
                         // traced sun visibility (x)
TLX_BLOCK_END(camera)
