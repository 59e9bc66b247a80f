// Camera and frame: what every pass of a frame sees.
TLX_BLOCK_BEGIN(CameraBlock, TLX_SET_VIEW, 0)
    TLX_MAT4(viewProj)   // Vulkan clip space
    TLX_VEC4(position)   // xyz camera position
    TLX_VEC4(viewport)   // xy size in pixels, zw 1 / size
    TLX_IVEC4(view)      // x debug view, y 1 = scene-linear output (EXR), z 1 = the view reads
                         // the probe diagnostics in place of probe light
TLX_BLOCK_END(camera)
