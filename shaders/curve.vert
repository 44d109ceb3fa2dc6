#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
// One polyline segment per instance, widened on screen into a quad of 2 * pc.params.x pixels and
// extended by half a width at each end so consecutive segments close their joints.
layout(location = 0) in vec3 p0;
layout(location = 1) in vec3 p1;
void main() {
  vec4 c0 = pc.view_proj * vec4(p0, 1.0);
  vec4 c1 = pc.view_proj * vec4(p1, 1.0);
  vec2 viewport = pc.params.yz;
  vec2 s0 = c0.xy / c0.w * viewport;
  vec2 s1 = c1.xy / c1.w * viewport;
  vec2 d = s1 - s0;
  d = length(d) > 1e-6 ? normalize(d) : vec2(1.0, 0.0);
  vec2 side = vec2(-d.y, d.x);
  int corner = gl_VertexIndex;  // two triangles: (0,1,2) (2,1,3) over ends t in {0,1} and sides +-1
  int k = corner < 3 ? corner : (corner == 3 ? 2 : (corner == 4 ? 1 : 3));
  float t = float(k & 1);
  float s = (k & 2) != 0 ? 1.0 : -1.0;
  vec4 c = t == 0.0 ? c0 : c1;
  vec2 offset_px = (side * s + d * (t * 2.0 - 1.0)) * pc.params.x;
  c.xy += offset_px * 2.0 / viewport * c.w;
  c.z -= pc.params.w * c.w;  // drawn over the surface it lies on
  gl_Position = c;
}
