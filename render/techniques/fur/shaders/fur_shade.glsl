// lucent GLSL 1: Klotzli & Olano's per-fragment reconstruction, shared by the tile (fur.frag), fur over
// a mesh (fur_mesh.frag) and the twin test (tests/render/fur_renderer_test.cpp, against
// fur::shade): a shell's 7 transfer layers (fur_gl.h: t_4k..t_4k+3 in layer 7 s + k, t_24 and the
// coverage in layer 7 s + 6) dotted with the light's 25 SH coefficients per channel.
#ifndef LUCENT_FUR_SHADE_GLSL
#define LUCENT_FUR_SHADE_GLSL

struct FurTexel {
  vec4 t[7];
};

FurTexel fur_fetch(sampler2DArray transfer, vec2 uv, int shell) {
  FurTexel f;
  for (int k = 0; k < 7; ++k) f.t[k] = texture(transfer, vec3(uv, float(7 * shell + k)));
  return f;
}

float fur_coverage(FurTexel f) { return f.t[6].y; }

/// sum_i c_i t_i per channel (not clamped).
vec3 fur_light(FurTexel f, vec4 r[7], vec4 g[7], vec4 b[7]) {
  vec3 sum = vec3(0.0);
  for (int k = 0; k < 6; ++k) sum += vec3(dot(f.t[k], r[k]), dot(f.t[k], g[k]), dot(f.t[k], b[k]));
  return sum + f.t[6].x * vec3(r[6].x, g[6].x, b[6].x);
}
#endif
