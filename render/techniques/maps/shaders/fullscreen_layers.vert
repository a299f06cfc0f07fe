#version 450 core
// lucent GLSL 1: a triangle covering the viewport, once per instance; the instance is the layer
// (mip_blur.geom routes it).
out vec2 v_uv;
flat out int v_layer;

void main() {
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);  // (0,0) (2,0) (0,2)
  v_uv = p;
  v_layer = gl_InstanceID;
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
