#version 450 core
// lucent GLSL 1: the hierarchical technique (Mertens et al. §5.4): the mesh from the viewer's camera with
// the per-vertex B the CPU gathered (Gouraud-interpolated to the fragments).
layout(location = 0) in vec3 a_position;  // mm
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_B;         // W mm^-2 per unit light, RGB

uniform mat4 u_view_proj;

out vec3 f_position;
out vec3 f_normal;
out vec3 f_B;

void main() {
  f_position = a_position;
  f_normal = a_normal;
  f_B = a_B;
  gl_Position = u_view_proj * vec4(a_position, 1.0);
}
