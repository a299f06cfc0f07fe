// Observations of a fit: bins or pixels of one channel, after exclusion and the noise floor
// (fit_residuals.h).
#include "fit_residuals.h"

namespace lucent::fit::detail {

Observations observations_for(const ProfileData& d, int c, double exclude_mm, bool use_2d,
                              const QualitySettings& q, int* below_noise) {
  Observations o;
  o.geometry = geometry_of(d);
  const auto keep = [&](double v, double se) {
    if (!(se > 0) || !std::isfinite(v) || !std::isfinite(se)) return false;
    if (v < 2 * se) {  // below the noise floor: a log-ratio there is meaningless
      ++*below_noise;
      return false;
    }
    return true;
  };
  if (use_2d) {
    const Samples2d& s = *d.samples_2d;
    o.radial = false;
    o.pixel = s.pixel_mm;
    o.linear = true;
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < s.size(); ++i) {
      const double v = s.value[c][i], se = s.standard_error[c][i];
      if (std::hypot(s.x_mm[i], s.y_mm[i]) >= exclude_mm && se > 0 && std::isfinite(v) &&
          std::isfinite(se)) {
        idx.push_back(i);
      }
    }
    const std::size_t stride =
        std::max<std::size_t>(1, (idx.size() + q.max_samples_2d - 1) / q.max_samples_2d);
    for (std::size_t k = 0; k < idx.size(); k += stride) {
      const std::size_t i = idx[k];
      const double v = s.value[c][i], se = s.standard_error[c][i];
      o.x.push_back(s.x_mm[i]);
      o.y.push_back(s.y_mm[i]);
      o.log_value.push_back(std::log(std::max(v, se)));
      o.inv_rel_se.push_back(std::max(v, se) / se);
      o.data_rel_se.push_back(se / std::max(v, se));
      o.value.push_back(v);
      o.inv_se.push_back(1 / se);
      o.data_se.push_back(se);
    }
  } else {
    const RadialBins& b = d.radial;
    if (b.pixel_mm > 0) {
      // Bins of pixel averages: model each as a pixel footprint at the bin's mean radius.
      o.radial = false;
      o.pixel = b.pixel_mm;
    }
    // The usable range ends where the profile sinks into the noise: at the first two consecutive
    // bins below the noise floor. Bins beyond are not fitted even when noise lifts one above it
    // (keeping those would select upward fluctuations and bias the tail).
    bool ended = false;
    for (std::size_t i = 0; i < b.size(); ++i) {
      if (b.r_mm[i] < exclude_mm) continue;
      const auto below = [&](std::size_t k) {
        return !(b.value[c][k] >= 2 * b.standard_error[c][k]) || !(b.standard_error[c][k] > 0);
      };
      if (!ended && below(i) && (i + 1 == b.size() || below(i + 1))) ended = true;
      if (ended) {
        ++*below_noise;
        continue;
      }
      if (!keep(b.value[c][i], b.standard_error[c][i])) continue;
      o.r.push_back(b.r_mm[i]);
      o.r0.push_back(b.r_inner_mm[i]);
      o.r1.push_back(b.r_outer_mm[i]);
      o.x.push_back(b.r_mm[i]);
      o.y.push_back(0.0);
      o.log_value.push_back(std::log(b.value[c][i]));
      o.inv_rel_se.push_back(b.value[c][i] / b.standard_error[c][i]);
      o.data_rel_se.push_back(b.standard_error[c][i] / b.value[c][i]);
    }
  }
  return o;
}

}  // namespace lucent::fit::detail
