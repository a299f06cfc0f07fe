// Start values of a fit (fit_start.h).
#include "fit_start.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "lucent/materials/albedo.h"
#include "lucent/materials/dipole.h"
#include "fit_residuals.h"
#include "model_prediction.h"

namespace lucent::fit::detail {
namespace {

// Far-field log-slope and total reflectance of one channel's radial bins: start values
// (docs/DESIGN.md §6).
double far_field_sigma_tr(const RadialBins& bins, int c) {
  std::vector<std::size_t> ok;
  for (std::size_t i = 0; i < bins.size(); ++i) {
    if (bins.value[c][i] > 3 * bins.standard_error[c][i] && bins.r_mm[i] > 0) ok.push_back(i);
  }
  if (ok.size() < 4) return 0.1;
  // The outer half of the usable bins: log(R r^3 / (1 + s r)) ~ const - s r.
  const std::vector<std::size_t> outer(ok.begin() + ok.size() / 2, ok.end());
  double s = 0.0;
  for (int iteration = 0; iteration < 4; ++iteration) {
    double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (std::size_t i : outer) {
      const double r = bins.r_mm[i];
      const double y = std::log(bins.value[c][i] * r * r * r / (1 + s * r));
      const double w = std::pow(bins.value[c][i] / bins.standard_error[c][i], 2);
      sw += w;
      sx += w * r;
      sy += w * y;
      sxx += w * r * r;
      sxy += w * r * y;
    }
    const double denominator = sw * sxx - sx * sx;
    if (!(denominator > 0)) break;
    s = std::max(1e-4, -(sw * sxy - sx * sy) / denominator);
  }
  return s;
}

double plane_total(const RadialBins& bins, int c, double sigma_tr) {
  double total = 0;
  for (std::size_t i = 0; i < bins.size(); ++i) {
    double r0 = bins.r_inner_mm[i], r1 = bins.r_outer_mm[i];
    if (!(r1 > r0)) {  // point samples: the annulus between the midpoints to the neighbours
      r0 = i == 0 ? 0.0 : 0.5 * (bins.r_mm[i - 1] + bins.r_mm[i]);
      r1 = i + 1 == bins.size() ? bins.r_mm[i] : 0.5 * (bins.r_mm[i] + bins.r_mm[i + 1]);
    }
    total += bins.value[c][i] * std::numbers::pi * (r1 * r1 - r0 * r0);
  }
  // Missing centre (first bin not at 0) and tail beyond the last bin: the far-field form
  // C e^(-s r)(1 + s r)/r^3 matched to the last bin, integrated analytically: 2 pi C e^(-s R) / R.
  if (bins.size() > 0) {
    const std::size_t last = bins.size() - 1;
    const double R = bins.r_outer_mm[last], r = bins.r_mm[last];
    const double C =
        bins.value[c][last] * r * r * r / ((1 + sigma_tr * r) * std::exp(-sigma_tr * r));
    if (std::isfinite(C) && C > 0) total += 2 * std::numbers::pi * C * std::exp(-sigma_tr * R) / R;
  }
  return total;
}


}  // namespace

StartValues start_values(const ProfileData& d, int c, double eta, bool relative, bool search) {
  StartValues sv;
  const double sigma_tr = far_field_sigma_tr(d.radial, c);
  double alpha = 0.99;
  const CaptureGeometry g = geometry_of(d);
  const double fresnel = fresnel_factor(g, eta, FitModel::kDipole);
  if (!relative) {
    const double total = plane_total(d.radial, c, sigma_tr) / fresnel;
    if (total > 0 && total < 1)
      alpha = materials::reduced_albedo_from_total_reflectance(total, eta);
    alpha = std::clamp(alpha, 0.05, 1 - 1e-6);
  } else {
    // Unknown scale: the albedo whose dipole shape (for this sigma_tr) best matches the data, the
    // scale from the mean log-ratio.
    double best = INFINITY;
    for (double one_minus = 0.5; one_minus > 1e-6; one_minus *= 0.7) {
      const double a = 1 - one_minus;
      const double st = sigma_tr / std::sqrt(3 * (1 - a));
      const materials::StandardDipole<double> dipole(
          materials::Medium<double>::from_reduced((1 - a) * st, a * st, eta));
      double sum = 0, sum2 = 0;
      int n = 0;
      for (std::size_t i = 0; i < d.radial.size(); ++i) {
        const double v = d.radial.value[c][i];
        if (!(v > 2 * d.radial.standard_error[c][i]) || d.radial.r_mm[i] <= 0) continue;
        const double diff = std::log(v) - std::log(fresnel * dipole.R_d(d.radial.r_mm[i]));
        sum += diff;
        sum2 += diff * diff;
        ++n;
      }
      if (n < 2) break;
      const double spread = sum2 / n - (sum / n) * (sum / n);
      if (spread < best) {
        best = spread;
        alpha = a;
        sv.log_scale = sum / n;
      }
    }
  }
  const double sigma_t_reduced = sigma_tr / std::sqrt(3 * (1 - alpha));
  sv.sigma_a = (1 - alpha) * sigma_t_reduced;
  sv.sigma_s_reduced = alpha * sigma_t_reduced;

  // The far-field slope and total need an exponential tail and most of the light inside the image;
  // a profile that ends within a diffusion length has neither. So also search a coarse grid of
  // (alpha', sigma_t') on a dozen bins and keep whichever start matches the data better: a few
  // thousand dipole evaluations, cheap next to the solve, and the solve starts in the right valley.
  std::vector<std::size_t> use;
  for (std::size_t i = 0; search && i < d.radial.size(); ++i) {
    if (d.radial.r_mm[i] > 0 && d.radial.value[c][i] > 2 * d.radial.standard_error[c][i])
      use.push_back(i);
  }
  if (use.size() >= 4) {
    std::vector<std::size_t> pick;
    for (int k = 0; k < 12; ++k)
      pick.push_back(use[std::min(use.size() - 1, k * (use.size() - 1) / 11)]);
    const double r_min = d.radial.r_mm[pick.front()], r_max = d.radial.r_mm[pick.back()];
    std::array<double, 12> log_data{}, w{};
    for (std::size_t k = 0; k < pick.size(); ++k) {
      const std::size_t i = pick[k];
      log_data[k] = std::log(d.radial.value[c][i]);
      const double inv_rel = d.radial.value[c][i] / d.radial.standard_error[c][i];
      w[k] = inv_rel * inv_rel;
    }
    const double log_fresnel = std::log(fresnel);
    const auto cost = [&](double sa, double ss, double* log_scale) {
      const materials::StandardDipole<double> dipole(materials::Medium<double>::from_reduced(sa, ss, eta));
      double sum = 0, sum2 = 0, wsum = 0;
      std::array<double, 12> diff{};
      for (std::size_t k = 0; k < pick.size(); ++k) {
        const double m = dipole.R_d(d.radial.r_mm[pick[k]]);
        if (!(m > 0)) return double(INFINITY);
        diff[k] = log_data[k] - log_fresnel - std::log(m);
        sum += w[k] * diff[k];
        wsum += w[k];
      }
      const double shift = relative ? sum / wsum : 0.0;
      for (std::size_t k = 0; k < pick.size(); ++k) sum2 += w[k] * (diff[k] - shift) * (diff[k] - shift);
      if (log_scale) *log_scale = shift;
      return sum2;
    };
    double best_shift = sv.log_scale;
    double best = cost(sv.sigma_a, sv.sigma_s_reduced, &best_shift);
    const double alphas[] = {0.05, 0.2,  0.4,   0.6,   0.8,   0.9,    0.95,
                             0.98, 0.99, 0.995, 0.998, 0.999, 0.9995, 0.9999};
    for (double a : alphas) {
      for (int k = 0; k < 16; ++k) {
        const double st = 0.2 / r_max * std::pow(100.0 * r_max / r_min, k / 15.0);
        double shift = 0;
        const double value = cost((1 - a) * st, a * st, &shift);
        if (value < best) {
          best = value;
          best_shift = shift;
          sv.sigma_a = (1 - a) * st;
          sv.sigma_s_reduced = a * st;
        }
      }
    }
    if (relative) sv.log_scale = best_shift;
  }
  return sv;
}

}  // namespace lucent::fit::detail
