#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
// A light disc with a dark rim.
layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 out_color;
void main() {
  float r = length(uv);
  if (r > 1.0) discard;
  out_color = vec4(r < 0.62 ? pc.color.rgb : vec3(0.02), 1.0);
}
