#version 450 core
// lucent GLSL 1: Banterle & Chalmers step 2, what a cube-map texel stores: the irradiance E of every light at
// the surface point it sees (the primary light shadowed by its shadow map, the others unshadowed:
// one shadow map per frame is the technique's budget) times the Fresnel transmittance into the
// object, lucent's exact unpolarised F_t (u_schlick: the seed's Schlick approximation instead).
// Alpha 1 marks covered texels.
#include "fresnel.glsl"
#include "sh_light.glsl"
in vec3 f_position;
in vec3 f_normal;
uniform sampler2D u_first_depth;  // unblurred, nearest
uniform float u_eta;
uniform bool u_schlick;
layout(location = 0) out vec4 out_color;

float transmittance(float cos_i) {
  if (!u_schlick) return fresnel_transmittance(cos_i, u_eta);
  float r0 = (u_eta - 1.0) / (u_eta + 1.0);
  r0 *= r0;
  float m = 1.0 - clamp(cos_i, 0.0, 1.0);
  return 1.0 - (r0 + (1.0 - r0) * m * m * m * m * m);
}

void main() {
  vec3 x = f_position;
  vec3 n = normalize(f_normal);
  vec3 sum = vec3(0.0);
  for (int l = 0; l < u_light_count; ++l) {
    vec3 w, E;
    sh_light_at(l, x, w, E);
    float cos_i = dot(n, w);
    if (!(cos_i > 0.0)) continue;
    if (l == u_primary) {
      vec2 uv = sh_shadow_uv(x);
      if (uv.x >= 0.0) {
        ivec2 size = textureSize(u_first_depth, 0);
        float first = texelFetch(u_first_depth, ivec2(uv * vec2(size)), 0).r;
        if (sh_distance(x) > first + sh_shadow_bias(n, w)) continue;
      }
    }
    sum += E * cos_i * transmittance(cos_i);
  }
  out_color = vec4(sum, 1.0);
}
