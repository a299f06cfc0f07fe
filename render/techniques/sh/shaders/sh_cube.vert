#version 450 core
// lucent GLSL 1: Banterle & Chalmers step 2, the mesh into one face of the external cube map: an orthographic
// camera along the face's axis with the bounding box scaled to the cube [-1, 1]^3 (the seed's fix
// of the "blindness" problem); u_face maps box coordinates to the face's (u, v, depth).
layout(location = 0) in vec3 a_position;  // mm
layout(location = 1) in vec3 a_normal;
uniform vec3 u_box_centre;
uniform vec3 u_box_half;  // > 0 on every axis
uniform mat4 u_face;
out vec3 f_position;
out vec3 f_normal;
void main() {
  f_position = a_position;
  f_normal = a_normal;
  gl_Position = u_face * vec4((a_position - u_box_centre) / u_box_half, 1.0);
}
