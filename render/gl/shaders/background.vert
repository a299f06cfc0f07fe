#version 450 core
// lucent GLSL 1: a triangle covering the viewport, with its normalised device coordinates.
out vec2 v_ndc;

void main() {
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2) * 2.0 - 1.0;  // (-1,-1) (3,-1) (-1,3)
  v_ndc = p;
  gl_Position = vec4(p, 1.0, 1.0);
}
