// Coefficient packing for the GLSL BSSRDF twins (see gl_bssrdf.h).
#include "gl_bssrdf.h"

#include <string>

namespace lucent::render::gl {

DdipoleChannelData ddipole_channel_data(const materials::Medium<double>& medium) {
  const auto c = materials::derive_coefficients(medium);
  return {float(c.alpha_prime), float(c.eta),          float(c.D),     float(c.sigma_tr),
          float(c.sigma_t),     float(c.d_e),          float(c.C_phi), float(c.C_E),
          float(c.A_ddipole),   float(c.normalisation)};
}

DipoleChannelData dipole_channel_data(const materials::Medium<double>& medium) {
  const auto c = materials::derive_coefficients(medium);
  return {float(c.alpha_prime), float(c.sigma_tr), float(c.z_r), float(c.z_v)};
}

void set_bssrdf_uniforms(GLuint program, const materials::Material& material) {
  const auto set = [program](const std::string& name, float value) {
    glProgramUniform1f(program, glGetUniformLocation(program, name.c_str()), value);
  };
  for (int channel = 0; channel < 3; ++channel) {
    const auto medium = material.medium(channel);
    const DdipoleChannelData dd = ddipole_channel_data(medium);
    const std::string d = "u_ddipole[" + std::to_string(channel) + "].";
    set(d + "alpha_prime", dd.alpha_prime);
    set(d + "eta", dd.eta);
    set(d + "D", dd.D);
    set(d + "sigma_tr", dd.sigma_tr);
    set(d + "sigma_t", dd.sigma_t);
    set(d + "d_e", dd.d_e);
    set(d + "C_phi", dd.C_phi);
    set(d + "C_E", dd.C_E);
    set(d + "A", dd.A);
    set(d + "normalisation", dd.normalisation);
    const DipoleChannelData sd = dipole_channel_data(medium);
    const std::string s = "u_dipole[" + std::to_string(channel) + "].";
    set(s + "alpha_prime", sd.alpha_prime);
    set(s + "sigma_tr", sd.sigma_tr);
    set(s + "z_r", sd.z_r);
    set(s + "z_v", sd.z_v);
  }
  set("u_eta", float(material.ior));
}

}  // namespace lucent::render::gl
