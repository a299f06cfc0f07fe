// lucent GLSL 1: a fur coat's transmittance to the skin, T(mu) (render/include/lucent/render/
// fur_coat.h, whose FurCoat::at this twins): u_fur_coat_nodes = 0 means no coat (T = 1).
#ifndef LUCENT_FUR_COAT_GLSL
#define LUCENT_FUR_COAT_GLSL
#define LUCENT_MAX_FUR_COAT_NODES 32
uniform int u_fur_coat_nodes;
uniform float u_fur_coat[LUCENT_MAX_FUR_COAT_NODES];

float fur_coat(float mu) {
  int n = u_fur_coat_nodes;
  if (n == 0) return 1.0;
  if (!(mu > 0.0)) return 0.0;
  if (mu >= 1.0) return u_fur_coat[n - 1];
  int k = clamp(int(mu * float(n)) - 1, 0, n - 2);
  float a = u_fur_coat[k], b = u_fur_coat[k + 1];
  float inv_a = float(n) / float(k + 1), inv_b = float(n) / float(k + 2);
  float t = (1.0 / mu - inv_a) / (inv_b - inv_a);
  float v = (a > 0.0 && b > 0.0) ? exp(mix(log(a), log(b), t)) : a + t * (b - a);
  return clamp(v, 0.0, 1.0);
}
#endif
