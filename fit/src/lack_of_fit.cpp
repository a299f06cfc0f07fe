// Lack of fit along the radius (lack_of_fit.h).
#include "lack_of_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace lucent::fit::detail {

RadialStructure radial_structure(const std::vector<double>& r, const double* e, int n,
                                 const double* model_share) {
  RadialStructure s;
  s.bins = n;
  if (n < 24) return s;
  std::vector<double> d;
  d.reserve(std::size_t(n - 1));
  for (int i = 0; i + 1 < n; ++i) d.push_back(std::abs(e[i + 1] - e[i]));
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  s.scale = std::max(1.4826 * d[d.size() / 2] / std::sqrt(2.0), 1e-12);
  // The data's share of each residual's error, a_i = sqrt(1 - b_i^2): white noise, the part the
  // first differences measure, so the data's own scale is scale / rms(a).
  double mean_a2 = 0;
  for (int i = 0; i < n; ++i) {
    const double b = model_share ? std::clamp(model_share[i], 0.0, 1.0) : 0.0;
    mean_a2 += 1 - b * b;
  }
  mean_a2 = std::max(mean_a2 / n, 1e-6);
  const double data_scale2 = s.scale * s.scale / mean_a2;
  // Segments of 8 bins or more, at most 8 of them: long enough for a run of one sign to stand out
  // of the noise, few enough that each is a distinct part of the profile.
  const int k = std::clamp(n / 8, 3, 8);
  for (int j = 0; j < k; ++j) {
    const int a = j * n / k, b = (j + 1) * n / k;
    double sum = 0, a2 = 0, model = 0;
    for (int i = a; i < b; ++i) {
      sum += e[i];
      const double m = model_share ? std::clamp(model_share[i], 0.0, 1.0) : 0.0;
      a2 += 1 - m * m;
      model += m;  // the model's error, in units of the residuals (the table's SEs taken as they are)
    }
    const double variance = data_scale2 * a2 + model * model;
    s.q += sum * sum / variance;
    s.mean.push_back(sum / std::sqrt(variance));
    s.r_mm.push_back(std::sqrt(r[std::size_t(a)] * r[std::size_t(b - 1)]));
  }
  // Wilson-Hilferty: (q / k)^(1/3) is nearly normal with mean 1 - 2 / (9k), variance 2 / (9k).
  const double v = 2.0 / (9.0 * k);
  s.z = (std::cbrt(s.q / k) - (1 - v)) / std::sqrt(v);
  return s;
}

std::string lack_of_fit_reason(const RadialStructure& s, char channel) {
  std::ostringstream why;
  why.precision(2);
  why << "the model leaves structure in channel " << channel << "'s residuals (runs of one sign "
      << "along the radius, " << std::fixed << s.z << std::defaultfloat
      << " SD beyond noise; a good fit stays below " << kMaxStructureZ << ")";
  const int k = s.segments();
  if (k == 0) return why.str();
  // Where the largest run sits, and which way it goes (positive: the model above the data).
  int worst = 0;
  for (int j = 1; j < k; ++j)
    if (std::abs(s.mean[j]) > std::abs(s.mean[worst])) worst = j;
  if (worst >= k / 2) {
    if (s.mean[worst] > 0) {
      // The data fall below the model in the far half: from the start of that run on.
      int from = worst;
      while (from > 0 && s.mean[from - 1] > 0) --from;
      why << ": the far tail falls faster than a semi-infinite sample allows. Is the sample "
          << "thinner than about " << std::max(0.1, s.r_mm[from]) << " mm? Give --thickness-mm";
    } else {
      why << ": the far tail falls slower than the sample's transport allows: veiling glare or "
             "stray light in the lens (a white reference through the same lens measures it), or "
             "a dark level left in the data";
    }
  } else {
    why << (s.mean[worst] > 0
                ? ": the profile near the beam is flatter than a pencil beam's: a beam footprint "
                  "or lens blur wider than assumed (give a white reference through the same "
                  "lens, or --beam-sigma-mm)"
                : ": the profile near the beam is sharper than the model's: another eta (--ior) "
                  "or g (--g), or a sample that is not a homogeneous slab");
  }
  return why.str();
}

}  // namespace lucent::fit::detail

namespace lucent::fit::detail {

double thinnest_semi_infinite_mm(double sigma_a, double sigma_s_reduced, double eta, double reach_mm,
                                 double tolerance) {
  const double st = sigma_a + sigma_s_reduced;
  if (!(st > 0) || !(reach_mm > 0)) return 0;
  const double D = 1 / (3 * st), sigma_tr = std::sqrt(3 * sigma_a * st), z_r = 1 / st;
  const double eta2 = eta * eta;
  const double f_dr = eta >= 1 ? -1.440 / eta2 + 0.710 / eta + 0.668 + 0.0636 * eta
                               : -0.4399 + 0.7099 / eta - 0.3319 / eta2 + 0.0636 / (eta2 * eta);
  const double z_b = 2 * (1 + f_dr) / (1 - f_dr) * D;  // extrapolated boundary distance
  // One source at depth z (positive: real, negative: image) seen at radius r on the surface.
  const auto term = [&](double z, double r) {
    const double d = std::sqrt(r * r + z * z);
    return z * (1 + sigma_tr * d) * std::exp(-sigma_tr * d) / (d * d * d);
  };
  const auto semi = [&](double r) { return term(z_r, r) + term(z_r + 2 * z_b, r); };
  const auto slab = [&](double r, double thickness) {
    const double period = 2 * (thickness + 2 * z_b);
    double sum = 0;
    for (int i = -20; i <= 20; ++i) {
      // Sources at 2 i (d + 2 z_b) + z_r, images at 2 i (d + 2 z_b) - z_r - 2 z_b.
      sum += term(i * period + z_r, r) - term(i * period - z_r - 2 * z_b, r);
    }
    return sum;
  };
  for (double d = 0.25; d <= 1e4; d *= 1.1) {
    bool holds = true;
    for (double r = reach_mm / 8; r <= reach_mm * 1.0001 && holds; r *= 1.25)
      holds = std::abs(slab(r, d) / semi(r) - 1) <= tolerance;
    if (holds) return d;
  }
  return std::numeric_limits<double>::infinity();
}

}  // namespace lucent::fit::detail
