#version 450
// One triangle covering the viewport; v is 0 at the top edge and 1 at the bottom.
layout(location = 0) out float v;
void main() {
  vec2 p = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);
  v = p.y;
  gl_Position = vec4(p * 2.0 - 1.0, 1.0, 1.0);
}
