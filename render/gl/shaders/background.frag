#version 450 core
// lucent GLSL 1: the environment map behind the object (or black), alpha 0 (no object).
#include "environment.glsl"

in vec2 v_ndc;
layout(location = 0) out vec4 out_color;

uniform mat4 u_inverse_view_proj;
uniform bool u_has_environment;
uniform vec3 u_backdrop;  // radiance where there is no environment map
uniform sampler2D u_environment;

void main() {
  if (!u_has_environment) {
    out_color = vec4(u_backdrop, 0.0);
    return;
  }
  vec4 near = u_inverse_view_proj * vec4(v_ndc, -1.0, 1.0);
  vec4 far = u_inverse_view_proj * vec4(v_ndc, 1.0, 1.0);
  out_color = vec4(environment_lookup(u_environment, far.xyz / far.w - near.xyz / near.w), 0.0);
}
