#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
// The surface's quads drawn as lines (polygon mode LINE) over surface.vert's outputs: a dark colour,
// lighter where the surface faces the viewer, so the mesh's shape reads through it.
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 0) out vec4 out_color;
void main() {
  float facing = abs(dot(normalize(world_normal), normalize(pc.eye.xyz - world_position)));
  out_color = vec4(pc.color.rgb * (0.7 + 0.6 * facing), 1.0);
}
