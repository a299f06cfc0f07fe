#version 450 core
// lucent GLSL 1: step 2 of Dal Corso 2014 (§5.2 "Render to radiance map"): the mesh from K directions,
// orthographic, one layer per direction, in one instanced draw.
#include "layered_mesh.glsl"

layout(std140, binding = 1) uniform LayerCameras {
  mat4 u_layer_view_proj[LUCENT_MAX_DIRECTIONS];  // world (mm) -> clip, orthographic
  vec4 u_layer_direction[LUCENT_MAX_DIRECTIONS];  // xyz: unit direction from the object to camera k
};

void main() { emit_layered_triangle(u_layer_view_proj[v_layer[0]]); }
