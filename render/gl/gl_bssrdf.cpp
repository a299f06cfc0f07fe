// Coefficient packing for the GLSL BSSRDF twins (see gl_bssrdf.h).
#include "gl_bssrdf.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "lucent/core/error.h"
#include "lucent/materials/angular.h"
#include "lucent/materials/fresnel.h"
#include "lucent/materials/geometry_factor.h"
#include "lucent/materials/radial_slices.h"
#include "lucent/materials/tabulated.h"
#include "lucent/materials/transport_table.h"

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

TabulatedChannelData tabulated_channel_data(const materials::Medium<double>& medium, int row) {
  const auto profile = materials::radial_profile_for(medium.g, medium.eta);
  const materials::TabulatedModel<double> model(*profile, medium);
  const std::vector<double>& x = profile->log_rho_nodes();
  TabulatedChannelData d;
  d.nodes = int(x.size());
  d.row = row;
  d.x0 = float(x.front());
  d.h = float(x[1] - x[0]);
  d.sigma_t = float(model.sigma_t_reduced());
  d.log_values.assign(x.size(), 0.0f);
  if (!(model.alpha_prime() > 0)) return d;  // scale 0: no subsurface light
  const auto& values = model.log_row(materials::TableQuantity::kRadiance);
  for (std::size_t j = 0; j < x.size(); ++j) d.log_values[j] = float(values[j]);
  d.scale = float(model.S_d_scale());
  return d;
}

void set_tabulated(GLuint program, const materials::Material& material, GLuint texture_unit,
                   Texture& rows) {
  std::array<TabulatedChannelData, 3> channels;
  for (int c = 0; c < 3; ++c) channels[std::size_t(c)] = tabulated_channel_data(material.medium(c), c);
  const int J = channels[0].nodes;
  std::vector<float> texels(std::size_t(J) * 3, 0.0f);
  for (int c = 0; c < 3; ++c) {
    if (channels[std::size_t(c)].nodes != J) throw Error("tabulated model: channels' tables differ in size");
    std::copy(channels[std::size_t(c)].log_values.begin(), channels[std::size_t(c)].log_values.end(),
              texels.begin() + std::ptrdiff_t(c) * J);
  }
  rows = create_texture(GL_TEXTURE_2D);
  glTextureStorage2D(rows.id(), 1, GL_R32F, J, 3);
  glTextureSubImage2D(rows.id(), 0, 0, 0, J, 3, GL_RED, GL_FLOAT, texels.data());
  glProgramUniform1i(program, glGetUniformLocation(program, "u_tabulated_rows"), GLint(texture_unit));
  for (int c = 0; c < 3; ++c) {
    const TabulatedChannelData& d = channels[std::size_t(c)];
    const std::string n = "u_tabulated[" + std::to_string(c) + "].";
    const auto loc = [&](const char* field) { return glGetUniformLocation(program, (n + field).c_str()); };
    glProgramUniform1f(program, loc("sigma_t"), d.sigma_t);
    glProgramUniform1f(program, loc("scale"), d.scale);
    glProgramUniform1f(program, loc("x0"), d.x0);
    glProgramUniform1f(program, loc("h"), d.h);
    glProgramUniform1i(program, loc("nodes"), d.nodes);
    glProgramUniform1i(program, loc("row"), d.row);
  }
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

void set_angular_uniforms(GLuint program, const materials::Material& material, bool on, bool skew) {
  glProgramUniform1i(program, glGetUniformLocation(program, "u_angular"), on ? 1 : 0);
  std::array<float, 3> mean_free_path{}, sigma_tr{};
  for (int c = 0; c < 3; ++c) {
    const auto d = materials::derive_coefficients(material.medium(c));
    if (on && skew && d.sigma_t_reduced > 0) {
      mean_free_path[std::size_t(c)] = float(1 / d.sigma_t_reduced);
      sigma_tr[std::size_t(c)] = float(d.sigma_tr);
    }
  }
  glProgramUniform3fv(program, glGetUniformLocation(program, "u_mean_free_path"), 1,
                      mean_free_path.data());
  glProgramUniform3fv(program, glGetUniformLocation(program, "u_sigma_tr"), 1, sigma_tr.data());
  if (!on) return;
  const materials::AngularFactor factor(material);
  constexpr int n = materials::AngularFactor::kNodes;
  std::vector<float> nodes(std::size_t(n) * 3);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c)
      nodes[std::size_t(3 * i + c)] = float(factor.nodes(c)[std::size_t(i)]);
  glProgramUniform3fv(program, glGetUniformLocation(program, "u_angular_nodes"), n, nodes.data());
}

void set_geometry_factor_uniforms(GLuint program, const materials::Material& material, bool on) {
  glProgramUniform1i(program, glGetUniformLocation(program, "u_geometry_factor"), on ? 1 : 0);
  if (!on) return;
  std::array<float, 12> channels{};
  for (int c = 0; c < 3; ++c) {
    const auto d = materials::derive_coefficients(material.medium(c));
    const std::size_t k = std::size_t(4 * c);
    channels[k] = float(d.sigma_tr);
    channels[k + 1] = float(d.z_r);
    channels[k + 2] = float(d.z_v);
    channels[k + 3] = d.scatters() ? 1.0f : 0.0f;
  }
  glProgramUniform4fv(program, glGetUniformLocation(program, "u_geometry_channels"), 3,
                      channels.data());
}

void set_fur_coat_uniforms(GLuint program, const std::optional<FurCoat>& coat) {
  const int n = coat ? int(coat->transmittance.size()) : 0;
  if (coat && (n < 2 || n > kMaxFurCoatNodes)) {
    throw Error("fur coat: expected 2.." + std::to_string(kMaxFurCoatNodes) +
                " elevations for the GPU, got " + std::to_string(n));
  }
  glProgramUniform1i(program, glGetUniformLocation(program, "u_fur_coat_nodes"), n);
  if (n > 0) {
    glProgramUniform1fv(program, glGetUniformLocation(program, "u_fur_coat"), n,
                        coat->transmittance.data());
  }
}

}  // namespace lucent::render::gl
