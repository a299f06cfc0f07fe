// Importance sampling of the radial profile (profile_sampling.h).
#include "profile_sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "lucent/materials/medium.h"

namespace lucent::render::detail {

RadialProfileDensity::RadialProfileDensity(const materials::Material& material,
                                           materials::DiffusionModel model, double max_radius_mm) {
  std::vector<int> channels;
  double mfp_min = std::numeric_limits<double>::infinity(), reach = 0;
  for (int c = 0; c < 3; ++c) {
    const auto k = materials::derive_coefficients(material.medium(c));
    if (!k.scatters()) continue;
    channels.push_back(c);
    const double mfp = 1.0 / k.sigma_t_reduced;
    mfp_min = std::min(mfp_min, mfp);
    reach = std::max(reach, k.sigma_tr > 0 ? std::max(60.0 / k.sigma_tr, 10 * mfp) : 1e3 * mfp);
  }
  if (channels.empty() || !(max_radius_mm > 0)) return;
  r_max_ = std::min(max_radius_mm, reach);
  r_lo_ = std::min(1e-4 * mfp_min, 1e-3 * r_max_);
  constexpr int kCells = 4096;
  step_ = std::log(r_max_ / r_lo_) / kCells;
  mass_.assign(kCells, 0.0);
  for (int c : channels) {
    // Midpoint rule in ln r on each cell of 2 pi r^2 P_c(r) (dA = 2 pi r^2 d ln r).
    std::vector<double> share(kCells);
    double sum = 0;
    for (int i = 0; i < kCells; ++i) {
      const double r = r_lo_ * std::exp(step_ * (i + 0.5));
      const double v = materials::radial_profile_value(material, c, model,
                                                       materials::TableQuantity::kRadiance, r);
      share[std::size_t(i)] = std::isfinite(v) && v > 0 ? r * r * v : 0;
      sum += share[std::size_t(i)];
    }
    if (!(sum > 0)) continue;
    for (int i = 0; i < kCells; ++i) mass_[std::size_t(i)] += share[std::size_t(i)] / sum;
  }
  cumulative_.assign(kCells + 1, 0.0);
  for (int i = 0; i < kCells; ++i)
    cumulative_[std::size_t(i) + 1] = cumulative_[std::size_t(i)] + mass_[std::size_t(i)];
  total_ = cumulative_.back();
}

double RadialProfileDensity::sample(double u, double* density, double* cdf) const {
  const double target = std::clamp(u, 0.0, 1.0) * total_;
  const std::size_t cells = mass_.size();
  std::size_t i = std::size_t(std::upper_bound(cumulative_.begin(), cumulative_.end(), target) -
                              cumulative_.begin());
  i = std::clamp<std::size_t>(i, 1, cells) - 1;
  while (!(mass_[i] > 0) && i + 1 < cells) ++i;  // empty cells carry no radii
  while (!(mass_[i] > 0) && i > 0) --i;
  const double within = std::clamp((target - cumulative_[i]) / mass_[i], 0.0, 1.0);
  const double r = r_lo_ * std::exp(step_ * (double(i) + within));
  // Density per ln r in cell i: mass_i / (total step); per area: that / (2 pi r^2).
  if (density) *density = mass_[i] / (total_ * step_) / (2 * std::numbers::pi * r * r);
  if (cdf) *cdf = (cumulative_[i] + within * mass_[i]) / total_;
  return r;
}

double RadialProfileDensity::density_per_mm2(double r) const {
  if (!valid() || !(r >= r_lo_) || !(r < r_max_)) return 0.0;
  const std::size_t i =
      std::min(mass_.size() - 1, std::size_t(std::floor(std::log(r / r_lo_) / step_)));
  return mass_[i] / (total_ * step_) / (2 * std::numbers::pi * r * r);
}

}  // namespace lucent::render::detail
