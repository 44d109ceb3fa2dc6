#version 450
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
// A neutral vertical gradient: pc.color at the top, pc.light.rgb at the bottom (linear RGB).
layout(location = 0) in float v;
layout(location = 0) out vec4 out_color;
void main() { out_color = vec4(mix(pc.color.rgb, pc.light.rgb, v), 1.0); }
