#version 450 core
// lucent GLSL 1: step 2b of Dal Corso 2014 (§5.4.2, Listing 5.11): level l+1 of the radiance maps from
// level l (bound through a texture view of level l alone, §5.3.6) with the seed's 13-tap filter
// (centre, +-1 and +-2 texels along each axis, the four diagonal neighbours), alpha-weighted.
// The maps hold sums (rgb) and frame counts (alpha, 0 where no surface), so the plain mean of the taps,
// divided later by its alpha, is the alpha-weighted mean sum_j c_j a_j / sum_j a_j of the per-texel
// averages c_j = rgb_j / a_j: empty texels weigh nothing and edges keep their values, as the seed's
// weights clamp(a, 0, 1) intend, without its max(sum of weights, 1) floor darkening the edges.
uniform sampler2DArray u_source;  // view of level l: bilinear, clamped

in vec2 g_uv;
flat in int g_layer;
layout(location = 0) out vec4 out_radiance;

void main() {
  vec2 step_ = 1.0 / vec2(textureSize(u_source, 0).xy);  // one texel of level l
  const vec2 kTaps[13] = vec2[13](vec2(0, 0), vec2(1, 0), vec2(-1, 0), vec2(0, 1), vec2(0, -1),
                                  vec2(2, 0), vec2(-2, 0), vec2(0, 2), vec2(0, -2), vec2(1, 1),
                                  vec2(-1, -1), vec2(1, -1), vec2(-1, 1));
  vec4 sum = vec4(0.0);
  for (int k = 0; k < 13; ++k) {
    sum += textureLod(u_source, vec3(g_uv + kTaps[k] * step_, float(g_layer)), 0.0);
  }
  out_radiance = sum / 13.0;
}
