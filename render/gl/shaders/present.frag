#version 450 core
// lucent GLSL 1: shows the linear final image on screen (lucent view): exposure, tone curve, sRGB
// (the twin of the PNG path, tone_map.glsl). The window framebuffer is not sRGB-encoding.
#include "tone_map.glsl"

in vec2 v_ndc;
layout(location = 0) out vec4 out_color;

uniform sampler2D u_image;  // linear radiance, rows bottom-up as rendered
uniform float u_exposure;

void main() {
  vec3 radiance = texture(u_image, v_ndc * 0.5 + 0.5).rgb;
  out_color = vec4(tone_map(radiance, u_exposure), 1.0);
}
