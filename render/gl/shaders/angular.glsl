// lucent GLSL 1: twin of materials/include/lucent/materials/angular.h (AngularFactor): the factor
// per channel of multiple scattering for light entering or leaving at an outside cosine, linear
// between the 33 nodes the CPU computes (gl::set_angular_uniforms); 1 when u_angular is off. And the
// oblique beam's skew of the radial profile (materials::oblique_displacement, oblique_skew):
// u_mean_free_path = 1 / sigma_t' per channel (mm; 0 when u_angular is off or the channel does not
// scatter, which makes the skew 1), u_sigma_tr its sigma_tr (mm^-1).
#ifndef LUCENT_ANGULAR_GLSL
#define LUCENT_ANGULAR_GLSL

uniform bool u_angular;
uniform vec3 u_angular_nodes[33];
uniform vec3 u_mean_free_path;
uniform vec3 u_sigma_tr;

const float kObliqueSkewNear = 0.8;

// The tangential part of the refracted direction of a beam entering along -w (w toward the light,
// or toward the eye for the exit side, by reciprocity) through a surface of normal n.
vec3 oblique_displacement(vec3 w, vec3 n, float eta) { return (dot(w, n) * n - w) / eta; }

float bessel_i0(float a) {
  float q = 0.25 * a * a;
  float term = 1.0, sum = 1.0;
  for (int k = 1; k <= 8; ++k) {
    term *= q / float(k * k);
    sum += term;
  }
  return sum;
}

// exp(a x^ . shift^) / I_0(a) per channel, a = |shift| min(near, l (sigma_tr + 3 / r)).
vec3 oblique_skew(vec3 x, vec3 shift) {
  float r = length(x), s = length(shift);
  if (!(r > 0.0) || !(s > 0.0)) return vec3(1.0);
  vec3 a = s * min(vec3(kObliqueSkewNear), u_mean_free_path * (u_sigma_tr + 3.0 / r));
  float c = dot(x, shift) / (r * s);
  return vec3(exp(a.r * c) / bessel_i0(a.r), exp(a.g * c) / bessel_i0(a.g),
              exp(a.b * c) / bessel_i0(a.b));
}

vec3 angular_factor(float cos_theta) {
  if (!u_angular) return vec3(1.0);
  float x = clamp(cos_theta, 0.0, 1.0) * 32.0;
  int i = min(int(x), 31);
  return mix(u_angular_nodes[i], u_angular_nodes[i + 1], x - float(i));
}

#endif
