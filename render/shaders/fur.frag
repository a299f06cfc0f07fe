#version 450 core
// lucent GLSL 1: seed 001's reconstruction: the 25-term dot product of the shell's transfer
// (layers 7 s .. 7 s + 6 of u_transfer, coefficients 4k..4k+3; layer 7 s + 6 holds t_24 in x and
// the shell's hair coverage in y) with the light's SH per channel; alpha = coverage (the skin:
// opaque). See fur_renderer.h for the shading.
#include "math.glsl"

in vec2 f_uv;
flat in int f_shell;
layout(location = 0) out vec4 out_color;

uniform sampler2DArray u_transfer;
uniform vec4 u_light_r[7];
uniform vec4 u_light_g[7];
uniform vec4 u_light_b[7];
uniform vec3 u_albedo;
uniform bool u_skin;

void main() {
  vec3 sum = vec3(0.0);
  float coverage = 0.0;
  for (int k = 0; k < 7; ++k) {
    vec4 t = texture(u_transfer, vec3(f_uv, float(7 * f_shell + k)));
    if (k == 6) {
      coverage = t.y;
      t = vec4(t.x, 0.0, 0.0, 0.0);
    }
    sum += vec3(dot(t, u_light_r[k]), dot(t, u_light_g[k]), dot(t, u_light_b[k]));
  }
  sum = max(sum, vec3(0.0));
  if (u_skin) {
    out_color = vec4(u_albedo / kPi * sum, 1.0);
  } else {
    out_color = vec4(u_albedo / (4.0 * kPi) * sum, coverage);
  }
}
