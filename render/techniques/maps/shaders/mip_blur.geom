#version 450 core
// lucent GLSL 1: routes each layer's full-screen triangle to its layer of the mip level being made.
layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;

in vec2 v_uv[];
flat in int v_layer[];
out vec2 g_uv;
flat out int g_layer;

void main() {
  for (int k = 0; k < 3; ++k) {
    gl_Layer = v_layer[0];
    g_layer = v_layer[0];
    g_uv = v_uv[k];
    gl_Position = gl_in[k].gl_Position;
    EmitVertex();
  }
  EndPrimitive();
}
