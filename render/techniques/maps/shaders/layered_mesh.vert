#version 450 core
// lucent GLSL 1: vertex stage of the layered mesh passes (light_map, radiance_map): world-space
// attributes through, the instance as the layer (see layered_mesh.glsl).
layout(location = 0) in vec3 a_position;  // mm
layout(location = 1) in vec3 a_normal;

out vec3 v_position;
out vec3 v_normal;
flat out int v_layer;

// The first layer of this draw: a frame split across calls (the viewer's frame budget) draws a
// run of layers, or one layer at a time in bands, each from its own layer.
uniform int u_first_layer = 0;

void main() {
  v_position = a_position;
  v_normal = a_normal;
  v_layer = u_first_layer + gl_InstanceID;
}
