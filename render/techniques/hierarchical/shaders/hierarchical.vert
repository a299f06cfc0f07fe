#version 450 core
// lucent GLSL 1: the hierarchical technique (Mertens et al. §5.4): the mesh from the viewer's camera with
// the per-vertex B the CPU gathered and its single scattering toward the eye (Gouraud-interpolated to the fragments).
layout(location = 0) in vec3 a_position;  // mm
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_B;         // W mm^-2 per unit light, RGB
layout(location = 3) in vec3 a_single;    // single-scattering radiance toward the eye (zeros: off)

uniform mat4 u_view_proj;

out vec3 f_position;
out vec3 f_normal;
out vec3 f_B;
out vec3 f_single;

void main() {
  f_position = a_position;
  f_normal = a_normal;
  f_B = a_B;
  f_single = a_single;
  gl_Position = u_view_proj * vec4(a_position, 1.0);
}
