// Camera and frame: what every pass of a frame sees.
TLX_BLOCK_BEGIN(CameraBlock, TLX_SET_VIEW, 0)
    TLX_MAT4(viewProj)   // Vulkan clip space
    TLX_MAT4(invViewProj)  // clip space back to world (the sky pass's view rays)
    TLX_VEC3_FLOAT(position, farPlane)  // camera position; far plane distance (metres)
    TLX_VEC2_VEC2(viewportSize, invViewportSize)  // pixels; 1 / pixels
    TLX_INT4(debugView, linearOutput, vertexAttribute, shadowFilter)  // debug view; 1 = scene-linear
                         // output (EXR); what the per-vertex attribute holds: 0 probe light, 1 the
                         // probe diagnostics, 2 the traced sun visibility (x); the shadow filter
                         // this view draws with, −1 the cascades' own (the water's planar
                         // reflection draws hard shadows: its waves blur any penumbra)
TLX_BLOCK_END(camera)
