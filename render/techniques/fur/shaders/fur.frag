#version 450 core
// lucent GLSL 1: Klotzli & Olano's reconstruction (fur_shade.glsl) on the tile's shells; alpha = the
// shell's hair coverage (the skin: opaque). See fur_renderer.h for the shading.
#include "math.glsl"
#include "fur_shade.glsl"

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
  FurTexel f = fur_fetch(u_transfer, f_uv, f_shell);
  vec3 sum = max(fur_light(f, u_light_r, u_light_g, u_light_b), vec3(0.0));
  if (u_skin) {
    out_color = vec4(u_albedo / kPi * sum, 1.0);
  } else {
    out_color = vec4(u_albedo / (4.0 * kPi) * sum, fur_coverage(f));
  }
}
