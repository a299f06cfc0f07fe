#version 450 core
// lucent GLSL 1: vertex stage of the layered mesh passes (light_map, radiance_map): world-space
// attributes through, the instance as the layer (see layered_mesh.glsl).
layout(location = 0) in vec3 a_position;  // mm
layout(location = 1) in vec3 a_normal;

out vec3 v_position;
out vec3 v_normal;
flat out int v_layer;

void main() {
  v_position = a_position;
  v_normal = a_normal;
  v_layer = gl_InstanceID;
}
