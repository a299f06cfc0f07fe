#version 450 core
// lucent GLSL 1: Banterle & Chalmers step 1, the mesh from the primary light (shadow map and depth peel).
layout(location = 0) in vec3 a_position;  // mm
uniform mat4 u_primary_view_proj;
out vec3 f_position;
void main() {
  f_position = a_position;
  gl_Position = u_primary_view_proj * vec4(a_position, 1.0);
}
