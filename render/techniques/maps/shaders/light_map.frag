#version 450 core
// lucent GLSL 1: step 1 of Dal Corso 2014: the light map stores, for the surface point nearest to the light
// in each texel, its position, its (shading) normal and the normal of the triangle it lies on
// (depth goes to the depth attachment). Coverage is w = 1; cleared texels (no surface) have w = 0.
in vec3 g_position;
in vec3 g_normal;
flat in vec3 g_face_normal;

layout(location = 0) out vec4 out_position;  // mm, w = 1
layout(location = 1) out vec4 out_normal;    // unit
layout(location = 2) out vec4 out_face_normal;  // unit, the triangle's plane

void main() {
  out_position = vec4(g_position, 1.0);
  out_normal = vec4(normalize(g_normal), 0.0);
  out_face_normal = vec4(g_face_normal, 0.0);
}
