#version 450
// One triangle over the whole viewport at the far plane (depth 1): drawn after the terrain with a
// less-or-equal depth test, it covers only what the terrain left empty.
layout(location = 0) out vec2 ndc;

void main() {
    vec2 p = vec2(float((gl_VertexIndex << 1) & 2), float(gl_VertexIndex & 2)) * 2.0 - 1.0;
    ndc = p;
    gl_Position = vec4(p, 1.0, 1.0);
}
