#version 450 core
// lucent GLSL 1: Banterle & Chalmers step 3, the projection of the cube map onto 9 SH coefficients per
// channel (eq. 6) by a two-stage reduction on the GPU, no read-back: stage 0, one invocation per
// texel of the six W x W faces (a 2D array of 6 layers, face order +X -X +Y -Y +Z -Z), each
// workgroup sums rgb E Y_lm dOmega over its 256 texels into 27 partial sums; stage 1, one
// workgroup adds the partial sums into u_coefficients (channel c, coefficient k at 9 c + k).
// dOmega is the differential texel solid angle of sh_texel_weight (the seed's weight), which
// sums to 4 pi to 6e-5 at W = 64 (tests).
layout(local_size_x = 256) in;
#include "sh_math.glsl"
layout(binding = 0) uniform sampler2DArray u_cube;  // rgb E F_t; texel (i, j) at (s, t) = i, j
layout(std430, binding = 0) buffer Partials { float partials[]; };
layout(std430, binding = 1) buffer Coefficients { float coefficients[27]; };
uniform int u_stage;
uniform int u_face_size;
uniform int u_group_count;  // stage 1: the number of partial sets stage 0 wrote

shared float s_sum[256];

float reduce(float v) {
  uint t = gl_LocalInvocationID.x;
  s_sum[t] = v;
  barrier();
  for (uint stride = 128u; stride > 0u; stride >>= 1) {
    if (t < stride) s_sum[t] += s_sum[t + stride];
    barrier();
  }
  float total = s_sum[0];
  barrier();
  return total;
}

void main() {
  uint t = gl_LocalInvocationID.x;
  if (u_stage == 0) {
    int w = u_face_size;
    int index = int(gl_GlobalInvocationID.x);
    vec3 value = vec3(0.0);
    float y[9];
    for (int k = 0; k < 9; ++k) y[k] = 0.0;
    if (index < 6 * w * w) {
      int face = index / (w * w);
      int i = index % w, j = (index / w) % w;
      float u = sh_texel_centre(i, w), v = sh_texel_centre(j, w);
      value = texelFetch(u_cube, ivec3(i, j, face), 0).rgb * sh_texel_weight(u, v, w);
      sh_basis(normalize(sh_cube_face_point(face, u, v)), y);
    }
    for (int c = 0; c < 3; ++c) {
      for (int k = 0; k < 9; ++k) {
        float total = reduce(value[c] * y[k]);
        if (t == 0u) partials[gl_WorkGroupID.x * 27u + uint(9 * c + k)] = total;
      }
    }
  } else {
    for (int k = 0; k < 27; ++k) {
      float v = 0.0;
      for (int g = int(t); g < u_group_count; g += 256) v += partials[g * 27 + k];
      float total = reduce(v);
      if (t == 0u) coefficients[k] = total;
    }
  }
}
