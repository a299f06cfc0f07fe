// lucent GLSL 1: twin of tone_curve() and srgb_encode() in render/core/tone_map.cpp
// (render/include/lucent/render/tone_map.h): Reinhard's x / (1 + x) per channel, then the sRGB
// transfer function.
#ifndef LUCENT_TONE_MAP_GLSL
#define LUCENT_TONE_MAP_GLSL

float tone_curve(float x) {
  if (!(x > 0.0)) return 0.0;  // negative and NaN
  if (isinf(x)) return 1.0;
  return x / (1.0 + x);
}

float srgb_encode(float linear) {
  float x = clamp(isnan(linear) ? 0.0 : linear, 0.0, 1.0);
  return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

vec3 tone_map(vec3 radiance, float exposure) {
  vec3 x = radiance * exposure;
  return vec3(srgb_encode(tone_curve(x.r)), srgb_encode(tone_curve(x.g)),
              srgb_encode(tone_curve(x.b)));
}

#endif
