// The tabulated model at oblique incidence (docs/DESIGN.md §4.2): one slice of an oblique transport
// table (transport_table.h; `lucent tabulate --incidence-deg`), the 2D profile of a semi-infinite
// slab under a pencil beam at a fixed incidence, eta and g, interpolated C1-smoothly in log value
// over ln rho (cubic Hermite, as the radial model), u = sqrt(1 - alpha') and the azimuth phi from
// the beam's direction of travel (Catmull-Rom on the wedge centres, continued evenly across 0 and
// pi, where the profile is symmetric). Templated on the scalar so that ceres::Jet carries exact
// derivatives in the coefficients; the position is data (double).
//
// Single scattering: in the radiance along the normal the beam's first scattering is a line on
// the surface (y = 0: a camera above sees each point of the refracted beam once), which wedges
// cannot hold. The table leaves it out (lucent tabulate skips the first collision's next-event
// estimate at oblique incidence) and ObliqueModel::line_in_square adds it in closed form.
#pragma once

#include <array>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "lucent/materials/fresnel.h"
#include "lucent/materials/tabulated.h"
#include "lucent/materials/transport_table.h"

namespace lucent::materials {

class ObliqueProfile {
 public:
  /// The slice of `table` at (eta, g, incidence_deg), each within 1e-6 of the slice's. Throws
  /// lucent::Error naming the table when it has none.
  ObliqueProfile(const TransportTable& table, double eta, double g, double incidence_deg);
  /// Whether `table` holds that slice.
  static bool has_slice(const TransportTable& table, double eta, double g, double incidence_deg);
  /// A copy with every measured entry's log value moved by a normal draw of its relative standard
  /// error (seeded), as TabulatedProfile::perturbed.
  ObliqueProfile perturbed(std::uint64_t seed) const;

  double eta() const { return eta_; }
  double g() const { return g_; }
  double incidence_deg() const { return incidence_deg_; }
  int phi_bins() const { return P_; }
  std::uint64_t photons() const { return photons_; }
  std::string to_string() const;

  /// Rows of log(value / alpha') at u, per quantity: P rows of J bin centres each, row p at
  /// index p * J (combined over the u nodes once for a medium, then read at many points).
  template <typename T>
  void rows_at(const T& u, std::array<std::vector<T>, kTableQuantities>& rows) const {
    const T uc = u < T(u_.back()) ? u : T(u_.back());
    const NodeWeights<T> wu = hermite_weights(u_, uc, false);
    const std::size_t block = std::size_t(P_) * std::size_t(J_);
    for (int q = 0; q < kTableQuantities; ++q) {
      std::vector<T>& row = rows[std::size_t(q)];
      row.assign(block, T(0));
      for (int b = 0; b < wu.count; ++b) {
        const double* src = f_[std::size_t(q)].data() + std::size_t(wu.first + b) * block;
        const T w = wu.w[std::size_t(b)];
        for (std::size_t i = 0; i < block; ++i) row[i] += w * T(src[i]);
      }
    }
  }

  /// log(value / alpha') from rows_at's rows at rho and azimuth phi in [0, pi].
  template <typename T>
  T log_value(const std::vector<T>& rows, const T& rho, double phi) const {
    // Catmull-Rom on the wedge centres (p + 1/2) pi / P, mirrored at 0 and pi.
    const double t = phi * P_ / std::numbers::pi - 0.5;
    const int i = int(std::floor(t));
    const double s = t - i;
    const double s2 = s * s, s3 = s2 * s;
    const double w[4] = {0.5 * (-s3 + 2 * s2 - s), 0.5 * (3 * s3 - 5 * s2 + 2),
                         0.5 * (-3 * s3 + 4 * s2 + s), 0.5 * (s3 - s2)};
    T sum(0);
    for (int c = 0; c < 4; ++c) {
      int p = i - 1 + c;
      if (p < 0) p = -p - 1;
      if (p >= P_) p = 2 * P_ - 1 - p;
      sum += T(w[c]) * interpolate_row(x_, rows.data() + std::size_t(p) * std::size_t(J_), rho);
    }
    return sum;
  }

  /// The table's relative standard error near (rho, phi, alpha'); infinity in an extrapolated
  /// tail or beyond the table.
  double relative_se(TableQuantity q, double rho, double phi, double alpha_prime) const;

 private:
  ObliqueProfile() = default;
  double eta_ = 1, g_ = 0, incidence_deg_ = 0;
  int P_ = 1, J_ = 0;
  std::vector<double> u_, x_;  // x = ln(rho) of the bin centres
  std::uint64_t photons_ = 0;
  // [quantity][(k * P + p) * J + j]: log(point value / alpha')
  std::array<std::vector<double>, kTableQuantities> f_;
  std::array<std::vector<float>, kTableQuantities> rel_se_;
};

/// The oblique model of one channel, in mm: the value at a surface point (x, y) from the entry
/// point, in the beam's frame (travelling toward +x).
template <typename T>
class ObliqueModel {
 public:
  ObliqueModel(const ObliqueProfile& profile, const Medium<T>& m) : profile_(&profile) {
    using std::pow;
    using std::sqrt;
    // The single-scattering line (radiance): pi L = delta(y) A e^(-k x) for x >= 0, from the
    // refracted beam d = (sin_t, 0, -cos_t) scattering toward the normal (cos angle -cos_t) and
    // leaving through the surface: collision density sigma_s e^(-sigma_t s) along the beam, s =
    // x / sin_t, the way up z = x cos_t / sin_t, exit T(normal) / eta^2, dx = sin_t ds.
    const double sin_t = std::sin(profile.incidence_deg() * std::numbers::pi / 180) / profile.eta();
    const double cos_t = std::sqrt(1 - sin_t * sin_t);
    if (sin_t > 1e-9) {
      const T g2 = m.g * m.g;
      const T phase = (T(1) - g2) / (T(4 * std::numbers::pi) *
                                     pow(T(1) + g2 + T(2) * m.g * T(cos_t), T(1.5)));
      const double exit = fresnel_transmittance(1.0, 1.0 / profile.eta()) /
                          (profile.eta() * profile.eta());
      line_a_ = T(std::numbers::pi * exit / sin_t) * m.sigma_s * phase;
      line_k_ = (m.sigma_a + m.sigma_s) * T((1 + cos_t) / sin_t);
    }
    sigma_t_reduced_ = m.sigma_a + m.sigma_s * (T(1) - m.g);
    alpha_prime_ = sigma_t_reduced_ > T(0) ? m.sigma_s * (T(1) - m.g) / sigma_t_reduced_ : T(0);
    if (alpha_prime_ > T(0)) {
      const T one_minus = T(1) - alpha_prime_;
      profile.rows_at(one_minus > T(0) ? sqrt(one_minus) : T(0), rows_);
      scale_ = sigma_t_reduced_ * sigma_t_reduced_ * alpha_prime_;
    }
  }
  /// Exitance, or pi L along the normal, per mm^2 per unit power entering.
  T at(TableQuantity q, double x_mm, double y_mm) const {
    if (!(alpha_prime_ > T(0))) return T(0);
    using std::exp;
    const double r = std::hypot(x_mm, y_mm);
    const double phi = r > 0 ? std::atan2(std::abs(y_mm), x_mm) : std::numbers::pi / 2;
    const T rho = T(r) * sigma_t_reduced_;
    const T floor(1e-12);
    return scale_ * exp(profile_->log_value(rows_[std::size_t(q)], rho > floor ? rho : floor, phi));
  }
  /// The single-scattering line's pi L averaged over the square [x0, x1) x [y0, y1) (mm, any
  /// frame), the beam travelling along the surface direction (tx, ty) (unit) from the origin: its
  /// integral over the segment inside, over the square's area. Radiance only (0 for exitance).
  T line_in_square(TableQuantity q, double x0, double x1, double y0, double y1, double tx,
                   double ty) const {
    if (q != TableQuantity::kRadiance || !(line_k_ > T(0))) return T(0);
    double lo = 0, hi = INFINITY;
    const auto clip = [&](double a0, double a1, double d) {
      if (std::abs(d) < 1e-12) {
        if (!(a0 <= 0 && 0 < a1)) hi = -1;  // the line runs outside (or on the far edge)
        return;
      }
      double t0 = a0 / d, t1 = a1 / d;
      if (t0 > t1) std::swap(t0, t1);
      lo = std::max(lo, t0);
      hi = std::min(hi, t1);
    };
    clip(x0, x1, tx);
    clip(y0, y1, ty);
    if (!(hi > lo)) return T(0);
    using std::exp;
    const T far = std::isfinite(hi) ? exp(-line_k_ * T(hi)) : T(0);
    return line_a_ / line_k_ * (exp(-line_k_ * T(lo)) - far) / T((x1 - x0) * (y1 - y0));
  }
  const T& alpha_prime() const { return alpha_prime_; }
  const T& sigma_t_reduced() const { return sigma_t_reduced_; }

 private:
  const ObliqueProfile* profile_;
  T sigma_t_reduced_, alpha_prime_, scale_{0};
  T line_a_{0}, line_k_{0};
  std::array<std::vector<T>, kTableQuantities> rows_;
};

/// Where an on-demand oblique slice is kept: $LUCENT_CACHE_DIR, else $XDG_CACHE_HOME/lucent, else
/// $HOME/.cache/lucent (empty when none is set).
std::filesystem::path oblique_cache_dir();

/// What a cache entry is: absent, a regular file lucent may open (a symlink to one included), or
/// something else (a FIFO, device, directory, dangling or looping link, an unreadable folder):
/// never opened (a FIFO would block the run), warned about, and replaced when lucent writes there.
enum class CacheEntry { kAbsent, kFile, kOther };
CacheEntry cache_entry(const std::filesystem::path& path);

}  // namespace lucent::materials
