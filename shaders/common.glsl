// Push constants shared by every pipeline (one 128-byte block, the minimum every device offers, no descriptor sets).
layout(push_constant) uniform Frame {
  mat4 view_proj;
  vec4 eye;     // xyz: camera position in world space
  vec4 color;   // per draw: linear RGB and alpha
  vec4 params;  // x: half width or radius in pixels, y, z: viewport size in pixels, w: depth pull toward the camera
  vec4 light;   // xyz: direction towards the key light, world space
} pc;
