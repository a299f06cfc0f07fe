// lucent GLSL 1: twin of materials/include/lucent/materials/angular.h (AngularFactor): the factor
// per channel of multiple scattering for light entering or leaving at an outside cosine, linear
// between the 33 nodes the CPU computes (gl::set_angular_uniforms); 1 when u_angular is off.
#ifndef LUCENT_ANGULAR_GLSL
#define LUCENT_ANGULAR_GLSL

uniform bool u_angular;
uniform vec3 u_angular_nodes[33];

vec3 angular_factor(float cos_theta) {
  if (!u_angular) return vec3(1.0);
  float x = clamp(cos_theta, 0.0, 1.0) * 32.0;
  int i = min(int(x), 31);
  return mix(u_angular_nodes[i], u_angular_nodes[i + 1], x - float(i));
}

#endif
