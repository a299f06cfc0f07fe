// The standard dipole's R_d(r) and its derivatives with respect to log sigma_a and log sigma_s', by
// hand: the fit's analytic Jacobian (FitOptions::analytic_derivatives). Held to the templated model
// in materials/ (value) and to ceres::Jet (derivatives) by tests/fit/dipole_gradient_test.cpp.
#pragma once

#include <cmath>
#include <numbers>

#include "lucent/materials/medium.h"

namespace lucent::fit::detail {

struct DipoleGradient {
  double value = 0;          ///< R_d, mm^-2
  double d_log_sigma_a = 0;  ///< dR_d / d log sigma_a
  double d_log_sigma_s = 0;  ///< dR_d / d log sigma_s'
};

/// Per-medium constants and their derivatives, computed once per evaluation.
class DipoleGradientModel {
 public:
  DipoleGradientModel(double sigma_a, double sigma_s_reduced, double eta) {
    const double st = sigma_a + sigma_s_reduced;
    alpha_ = sigma_s_reduced / st;
    sigma_tr_ = std::sqrt(3 * sigma_a * st);
    z_r_ = 1 / st;
    const double A =
        materials::derive_coefficients(materials::Medium<double>{0, 1, 0, eta}).A_dipole;
    virtual_factor_ = 1 + 4 * A / 3;  // z_v = z_r (1 + 4A/3), since D = z_r / 3
    z_v_ = z_r_ * virtual_factor_;
    const double st2 = st * st;
    d_alpha_[0] = -sigma_s_reduced * sigma_a / st2;
    d_alpha_[1] = sigma_s_reduced * sigma_a / st2;
    d_sigma_tr_[0] = sigma_tr_ > 0 ? 3 * sigma_a * (st + sigma_a) / (2 * sigma_tr_) : 0;
    d_sigma_tr_[1] = sigma_tr_ > 0 ? 3 * sigma_a * sigma_s_reduced / (2 * sigma_tr_) : 0;
    d_z_r_[0] = -sigma_a / st2;
    d_z_r_[1] = -sigma_s_reduced / st2;
  }

  DipoleGradient at(double r) const {
    double f_r, fz_r, fs_r, f_v, fz_v, fs_v;
    source(z_r_, r, f_r, fz_r, fs_r);
    source(z_v_, r, f_v, fz_v, fs_v);
    const double k = 1 / (4 * std::numbers::pi);
    const double sum = f_r + f_v;
    DipoleGradient g;
    g.value = k * alpha_ * sum;
    for (int p = 0; p < 2; ++p) {
      const double d_sum =
          fz_r * d_z_r_[p] + fz_v * d_z_r_[p] * virtual_factor_ + (fs_r + fs_v) * d_sigma_tr_[p];
      (p == 0 ? g.d_log_sigma_a : g.d_log_sigma_s) = k * (d_alpha_[p] * sum + alpha_ * d_sum);
    }
    return g;
  }

 private:
  // f(z) = z (1 + s d) e^(-s d) / d^3, d = sqrt(r^2 + z^2), s = sigma_tr; df/dz and df/ds.
  void source(double z, double r, double& f, double& f_z, double& f_s) const {
    const double d2 = r * r + z * z, d = std::sqrt(d2);
    const double sd = sigma_tr_ * d;
    const double e = std::exp(-sd);
    const double g = (1 + sd) * e / (d2 * d);
    const double g_d = -e * (sd * sd + 3 * sd + 3) / (d2 * d2);
    f = z * g;
    f_z = g + z * z * g_d / d;
    f_s = -z * sigma_tr_ * e / d;
  }

  double alpha_, sigma_tr_, z_r_, z_v_, virtual_factor_;
  double d_alpha_[2], d_sigma_tr_[2], d_z_r_[2];
};

}  // namespace lucent::fit::detail
