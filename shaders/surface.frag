#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
// Two-sided Blinn-Phong: a key light, a dimmer fill from the viewer and a sky/ground ambient.
// pc.color.a < 1 draws a see-through surface (the reference mesh).
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 0) out vec4 out_color;
void main() {
  vec3 to_eye = normalize(pc.eye.xyz - world_position);
  vec3 n = normalize(world_normal);
  if (dot(n, to_eye) < 0.0) n = -n;  // the back of an open surface is lit like its front
  vec3 key = normalize(pc.light.xyz);
  float diffuse = max(dot(n, key), 0.0);
  float fill = max(dot(n, to_eye), 0.0);
  float specular = pow(max(dot(n, normalize(key + to_eye)), 0.0), 48.0);
  vec3 ambient = mix(vec3(0.10, 0.09, 0.08), vec3(0.16, 0.17, 0.20), n.z * 0.5 + 0.5);
  vec3 albedo = pc.color.rgb;
  vec3 lit = albedo * (ambient + 0.80 * diffuse + 0.18 * fill) + vec3(0.22) * specular;
  out_color = vec4(lit, pc.color.a);
}
