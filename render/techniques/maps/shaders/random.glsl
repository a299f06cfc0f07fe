// lucent GLSL 1: per-texel random numbers for the radiance map's disc rotation (Dal Corso 2014 §5.4.1).
// The seed's generators (sine, linear shift, LCG) work on floats or signed ints with visible
// periodicity; this is the PCG hash (Jarzynski and Olano 2020, "Hash Functions for GPU Rendering"),
// a full 32-bit avalanche on unsigned integers.
#ifndef LUCENT_RANDOM_GLSL
#define LUCENT_RANDOM_GLSL

uint pcg_hash(uint v) {
  uint state = v * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

// Uniform in [0, 1), different for every texel of every layer.
float texel_random(ivec2 texel, int layer) {
  uint h = pcg_hash(uint(texel.x) + pcg_hash(uint(texel.y) + pcg_hash(uint(layer))));
  return float(h >> 8) * (1.0 / 16777216.0);
}

#endif
