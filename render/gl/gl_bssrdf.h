// The BSSRDF coefficients as the GLSL twins (render/techniques/maps/shaders/bssrdf_ddipole.glsl,
// bssrdf_dipole.glsl) receive them: derived on the CPU in double by materials::derive_coefficients
// and rounded once to float, as the C++ float models do.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "gl_api.h"
#include "gl_program.h"
#include "lucent/materials/material.h"
#include "lucent/materials/medium.h"
#include "lucent/render/fur_coat.h"

namespace lucent::render::gl {

/// std430 image of GLSL `DdipoleChannel` (same member order).
struct DdipoleChannelData {
  float alpha_prime, eta, D, sigma_tr, sigma_t, d_e, C_phi, C_E, A, normalisation;
};
static_assert(sizeof(DdipoleChannelData) == 10 * sizeof(float));

/// std430 image of GLSL `DipoleChannel` (same member order).
struct DipoleChannelData {
  float alpha_prime, sigma_tr, z_r, z_v;
};
static_assert(sizeof(DipoleChannelData) == 4 * sizeof(float));

/// GLSL `TabulatedChannel` (bssrdf_tabulated.glsl), and its row of log values.
struct TabulatedChannelData {
  float sigma_t, scale, x0, h;
  int nodes, row;
  std::vector<float> log_values;  ///< nodes values: TabulatedProfile::rows_at, quantity radiance
};

/// The tabulated model of one channel at its (alpha', eta, g), from the default transport table;
/// `row` is its row in the texture. Throws lucent::Error where the table does not reach the medium
/// (g or eta outside it).
TabulatedChannelData tabulated_channel_data(const materials::Medium<double>& medium, int row);

/// A 2D texture of the material's three tabulated rows (R32F, nodes x 3), and the uniforms
/// `u_tabulated[0..2]` of `program`.
void set_tabulated(GLuint program, const materials::Material& material, GLuint texture_unit,
                   Texture& rows);

DdipoleChannelData ddipole_channel_data(const materials::Medium<double>& medium);
DipoleChannelData dipole_channel_data(const materials::Medium<double>& medium);

/// Sets `u_ddipole[0..2]` and `u_dipole[0..2]` (uniform arrays of the structs above) and `u_eta` in
/// `program` (which must be in use) from the material's three channels.
void set_bssrdf_uniforms(GLuint program, const materials::Material& material);

inline constexpr int kMaxFurCoatNodes = 32;  ///< LUCENT_MAX_FUR_COAT_NODES of fur_coat.glsl

/// Sets `u_fur_coat_nodes` and `u_fur_coat` (fur_coat.glsl) in `program`: the coat's nodes, or
/// 0 nodes (T = 1) without one. Throws lucent::Error for a coat of more than kMaxFurCoatNodes.
void set_fur_coat_uniforms(GLuint program, const std::optional<FurCoat>& coat);

/// Sets `u_angular` and `u_angular_nodes` (angular.glsl) in `program`: the material's angular
/// factor of multiple scattering (materials/angular.h) when `on`, else off (a factor of 1); and
/// `u_mean_free_path`, `u_sigma_tr`: the oblique skew's (materials::oblique_skew) when `on` and
/// `skew`, else zero (a skew of 1).
void set_angular_uniforms(GLuint program, const materials::Material& material, bool on,
                          bool skew = true);

/// Sets `u_geometry_factor` and `u_geometry_channels` (geometry_factor.glsl) in `program`: the
/// material's dipole coefficients for the shape's factor (materials/geometry_factor.h) when `on`,
/// else off (a factor of 1).
void set_geometry_factor_uniforms(GLuint program, const materials::Material& material, bool on);

}  // namespace lucent::render::gl
