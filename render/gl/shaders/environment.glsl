// lucent GLSL 1: lat-long environment lookups, twin of latlong_coordinates() and
// environment_lookup() in render/core/environment.cpp (render/include/lucent/render/environment.h):
// u = phi / 2 pi with phi = atan2(-x, z) in [0, 2 pi), v = theta / pi from +y; row v = 0 on top.
// The texture is bilinear, repeating in u and clamped in v, as the CPU lookup.
#ifndef LUCENT_ENVIRONMENT_GLSL
#define LUCENT_ENVIRONMENT_GLSL

#include "math.glsl"

vec2 latlong_coordinates(vec3 direction) {
  vec3 d = normalize(direction);
  float phi = atan(-d.x, d.z);
  if (phi < 0.0) phi += 2.0 * kPi;
  float u = phi / (2.0 * kPi);
  if (u >= 1.0) u = 0.0;
  return vec2(u, acos(clamp(d.y, -1.0, 1.0)) / kPi);
}

vec3 environment_lookup(sampler2D map, vec3 direction) {
  return textureLod(map, latlong_coordinates(direction), 0.0).rgb;
}

#endif
