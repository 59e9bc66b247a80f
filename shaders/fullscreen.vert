#version 450
// One triangle over the whole viewport at the far plane (depth 0, reversed Z): drawn after the
// terrain with a greater-or-equal depth test, it covers only what the terrain left empty.
layout(location = 0) out vec2 ndc;

void main() {
    vec2 p = vec2(float((gl_VertexIndex << 1) & 2), float(gl_VertexIndex & 2)) * 2.0 - 1.0;
    ndc = p;
    gl_Position = vec4(p, 0.0, 1.0);
}
