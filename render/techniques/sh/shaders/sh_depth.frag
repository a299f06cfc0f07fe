#version 450 core
// lucent GLSL 1: Banterle & Chalmers step 1. The first pass keeps the nearest surface along the primary
// light's rays (depth test GL_LESS) and writes its distance; the peeling pass (u_peel) discards
// everything up to the first surface plus the bias, so the depth test keeps the second surface
// (the seed's Figure 9: points beyond it get no scattering term).
#include "sh_light.glsl"
in vec3 f_position;
uniform bool u_peel;
uniform sampler2D u_first_depth;  // nearest, texel for texel with this pass
layout(location = 0) out float out_distance;
void main() {
  float t = sh_distance(f_position);
  if (u_peel) {
    float first = texelFetch(u_first_depth, ivec2(gl_FragCoord.xy), 0).r;
    // The bias grows with the depth slope across the texel (fwidth), as a slope-scaled bias.
    if (t <= first + u_shadow_bias_mm + 2.0 * fwidth(t)) discard;
  }
  out_distance = t;
}
