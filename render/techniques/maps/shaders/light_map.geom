#version 450 core
// lucent GLSL 1: step 1 of Dal Corso 2014 (§5.2 "Light buffer"): every light's view of the mesh, one layer
// per light, in one instanced draw.
#include "layered_mesh.glsl"

layout(std140, binding = 0) uniform LightMatrices {
  mat4 u_light_view_proj[LUCENT_MAX_LIGHTS];  // world (mm) -> clip; orthographic or perspective
};

void main() { emit_layered_triangle(u_light_view_proj[v_layer[0]]); }
