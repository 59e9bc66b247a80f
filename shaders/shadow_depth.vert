#version 450
// The terrain into one cascade's shadow map: depth only, the cascade's light projection in a push
// constant.
layout(location = 0) in vec3 inPosition;
layout(push_constant) uniform Cascade { mat4 lightViewProj; } cascade;

void main() { gl_Position = cascade.lightViewProj * vec4(inPosition, 1.0); }
