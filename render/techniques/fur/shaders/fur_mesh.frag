#version 450 core
// lucent GLSL 1: fur over a mesh (fur_mesh.cpp): the tile's transfer by triplanar projection (the
// tile u_tile_mm wide on the planes across world x, y and z, blended by |n_a|^4) dotted with the
// light's SH in the vertex frames (u_vertex_light: per vertex 3 channels x 7 vec4, interpolated
// with the barycentric weights). Colour: the hairs' albedo / (4 pi) times the light reaching them
// (fur_renderer.h), alpha: their coverage.
#include "math.glsl"
#include "fur_shade.glsl"

layout(std430, binding = 3) readonly buffer VertexLight { vec4 b_light[]; };

in vec3 f_position;
in vec3 f_normal;
in vec3 f_barycentric;
flat in ivec3 f_vertices;
flat in int f_shell;
layout(location = 0) out vec4 out_color;

uniform sampler2DArray u_transfer;
uniform float u_tile_mm;
uniform vec3 u_albedo;
uniform bool u_depth_only;

void main() {
  if (u_depth_only) {
    out_color = vec4(0.0);
    return;
  }
  vec3 w = pow(abs(normalize(f_normal)), vec3(4.0));
  w /= w.x + w.y + w.z;
  vec2 uv[3] = vec2[](f_position.yz, f_position.zx, f_position.xy);
  FurTexel f;
  for (int k = 0; k < 7; ++k) f.t[k] = vec4(0.0);
  for (int a = 0; a < 3; ++a) {
    if (w[a] < 1e-3) continue;
    FurTexel fa = fur_fetch(u_transfer, uv[a] / u_tile_mm, f_shell);
    for (int k = 0; k < 7; ++k) f.t[k] += w[a] * fa.t[k];
  }
  vec4 r[7], g[7], b[7];
  for (int k = 0; k < 7; ++k) {
    r[k] = vec4(0.0);
    g[k] = vec4(0.0);
    b[k] = vec4(0.0);
    for (int c = 0; c < 3; ++c) {
      int base = 21 * f_vertices[c];
      r[k] += f_barycentric[c] * b_light[base + k];
      g[k] += f_barycentric[c] * b_light[base + 7 + k];
      b[k] += f_barycentric[c] * b_light[base + 14 + k];
    }
  }
  vec3 light = max(fur_light(f, r, g, b), vec3(0.0));
  out_color = vec4(u_albedo / (4.0 * kPi) * light, fur_coverage(f));
}
