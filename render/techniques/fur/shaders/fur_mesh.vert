#version 450 core
// lucent GLSL 1: fur over a mesh (the extension of Klotzli & Olano, fur_mesh.cpp): instance s is shell s,
// the mesh pushed out along its vertex normals by (s + 0.5) u_spacing_mm (u_depth_only: the mesh
// itself, for the depth that hides the shells behind it). Drawn without an index buffer: vertex i
// is corner i % 3 of triangle i / 3, read from the buffers; the fragment gets the triangle's three
// vertex ids and its barycentric weights, to interpolate the per-vertex light.
layout(std430, binding = 0) readonly buffer Positions { float b_position[]; };
layout(std430, binding = 1) readonly buffer Normals { float b_normal[]; };
layout(std430, binding = 2) readonly buffer Indices { uint b_index[]; };

uniform mat4 u_view_proj;
uniform float u_spacing_mm;
uniform bool u_depth_only;

out vec3 f_position;  // mm
out vec3 f_normal;
out vec3 f_barycentric;
flat out ivec3 f_vertices;
flat out int f_shell;

vec3 load(int which, uint v) {
  return which == 0 ? vec3(b_position[3 * v], b_position[3 * v + 1], b_position[3 * v + 2])
                    : vec3(b_normal[3 * v], b_normal[3 * v + 1], b_normal[3 * v + 2]);
}

void main() {
  int triangle = gl_VertexID / 3, corner = gl_VertexID % 3;
  uint v = b_index[3 * triangle + corner];
  f_vertices = ivec3(b_index[3 * triangle], b_index[3 * triangle + 1], b_index[3 * triangle + 2]);
  f_barycentric = vec3(corner == 0, corner == 1, corner == 2);
  vec3 n = normalize(load(1, v));
  f_shell = gl_InstanceID;
  float offset = u_depth_only ? 0.0 : (float(gl_InstanceID) + 0.5) * u_spacing_mm;
  // f_position is the surface point under the shell: every shell reads the tile at the same uv
  // (the pushed-out point would slide the texture along oblique faces, shell by shell).
  f_position = load(0, v);
  f_normal = n;
  gl_Position = u_view_proj * vec4(f_position + offset * n, 1.0);
}
