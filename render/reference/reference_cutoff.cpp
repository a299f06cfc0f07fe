// subsurface_cutoff_mm (reference_renderer.h): how far the reference's gather needs to look.
#include <cmath>
#include <vector>

#include "lucent/render/reference_renderer.h"
#include "reference_common.h"

namespace lucent::render {

using namespace detail;

double subsurface_cutoff_mm(const materials::Medium<double>& medium, DiffusionModel model,
                            double tolerance) {
  const auto c = materials::derive_coefficients(medium);
  if (!c.scatters() || !(c.sigma_tr > 0)) return kInf;
  const ChannelBssrdf bssrdf(medium, model);
  // Normal incidence on the plane z = 0: profile(r) = S_d(0, z, z, (r, 0, 0), z), integrated with
  // weight 2 pi r dr on a log grid (trapezoid in ln r) from far inside a mean free path to 60
  // diffusion lengths, where e^(-60) leaves nothing.
  const double mfp = 1.0 / c.sigma_t_reduced;
  const double r_lo = 1e-6 * mfp, r_hi = std::max(60.0 / c.sigma_tr, 1e3 * mfp);
  const int n = 6000;
  const Vec3d z(0, 0, 1);
  std::vector<double> r(n), cumulative(n, 0.0);
  double previous = 0;
  for (int i = 0; i < n; ++i) {
    r[i] = r_lo * std::pow(r_hi / r_lo, double(i) / (n - 1));
    const double f = bssrdf(Vec3d::Zero(), z, z, Vec3d(r[i], 0, 0), z) * r[i] * r[i];
    if (i > 0) cumulative[i] = cumulative[i - 1] + 0.5 * (f + previous) * std::log(r[i] / r[i - 1]);
    previous = f;
  }
  const double total = cumulative.back();
  if (!(total > 0)) return kInf;
  for (int i = 0; i < n; ++i) {
    if (total - cumulative[i] <= tolerance * total) {
      return r[i] >= 0.99 * r_hi ? kInf : r[i];
    }
  }
  return kInf;
}

}  // namespace lucent::render
