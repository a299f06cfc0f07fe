#version 450 core
// lucent GLSL 1: Banterle & Chalmers step 1, the separable Gaussian blur of the first depth ("8x8" in the
// seed; here sigma in texels, the kernel to 3 sigma). Only texels that hold a surface are averaged
// (the weights renormalised over them), so the silhouette is not pulled toward the empty
// background; an empty texel stays empty.
#include "sh_light.glsl"
in vec2 v_ndc;
uniform sampler2D u_source;
uniform ivec2 u_step;  // (1, 0) or (0, 1)
uniform float u_sigma_texels;
layout(location = 0) out float out_distance;
void main() {
  ivec2 size = textureSize(u_source, 0);
  ivec2 p = ivec2(gl_FragCoord.xy);
  float centre = texelFetch(u_source, p, 0).r;
  if (centre >= kShNoSurface * 0.5 || !(u_sigma_texels > 0.0)) {
    out_distance = centre;
    return;
  }
  int radius = int(ceil(3.0 * u_sigma_texels));
  float sum = 0.0, weight = 0.0;
  for (int k = -radius; k <= radius; ++k) {
    ivec2 q = clamp(p + k * u_step, ivec2(0), size - 1);
    float v = texelFetch(u_source, q, 0).r;
    if (v >= kShNoSurface * 0.5) continue;
    float w = exp(-0.5 * float(k * k) / (u_sigma_texels * u_sigma_texels));
    sum += w * v;
    weight += w;
  }
  out_distance = sum / weight;
}
