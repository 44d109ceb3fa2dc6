#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
// A round marker of radius pc.params.x pixels per instance (a network vertex).
layout(location = 0) in vec3 position;
layout(location = 0) out vec2 uv;
void main() {
  int corner = gl_VertexIndex;
  int k = corner < 3 ? corner : (corner == 3 ? 2 : (corner == 4 ? 1 : 3));
  uv = vec2((k & 1) != 0 ? 1.0 : -1.0, (k & 2) != 0 ? 1.0 : -1.0);
  vec4 c = pc.view_proj * vec4(position, 1.0);
  c.xy += uv * pc.params.x * 2.0 / pc.params.yz * c.w;
  c.z -= pc.params.w * c.w;
  gl_Position = c;
}
