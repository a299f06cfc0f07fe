#version 450 core
// lucent GLSL 1: step 3 of Dal Corso 2014: the mesh from the viewer's camera.
layout(location = 0) in vec3 a_position;  // mm
layout(location = 1) in vec3 a_normal;

uniform mat4 u_view_proj;

out vec3 f_position;
out vec3 f_normal;

void main() {
  f_position = a_position;
  f_normal = a_normal;
  gl_Position = u_view_proj * vec4(a_position, 1.0);
}
