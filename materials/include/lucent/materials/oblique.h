// The tabulated model at oblique incidence (DESIGN §4.2): one slice of an oblique transport table
// (transport_table.h; `lucent tabulate --incidence-deg`), the 2D profile of a semi-infinite slab
// under a pencil beam at a fixed incidence, eta and g, interpolated C1-smoothly in log value over
// ln rho (cubic Hermite, as the radial model), u = sqrt(1 - alpha') and the azimuth phi from the
// beam's direction of travel (Catmull-Rom on the wedge centres, continued evenly across 0 and pi,
// where the profile is symmetric). Templated on the scalar so that ceres::Jet carries exact
// derivatives in the coefficients; the position is data (double).
//
// Known limit: in the radiance quantity the first scattering along the refracted beam is a line
// on the surface (y = 0, a camera above sees each point of the beam once); the table spreads it
// over its innermost wedges, so on that line near the entry point (rho < ~3) the model is low
// and beside it high, by ~10% at alpha' 0.6 and within the Monte Carlo noise at alpha' >= 0.93
// (tests/acquire/oblique_table_test.cpp). An oblique fit starts beyond two pixels.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

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
    using std::sqrt;
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
  const T& alpha_prime() const { return alpha_prime_; }
  const T& sigma_t_reduced() const { return sigma_t_reduced_; }

 private:
  const ObliqueProfile* profile_;
  T sigma_t_reduced_, alpha_prime_, scale_{0};
  std::array<std::vector<T>, kTableQuantities> rows_;
};

/// Where an on-demand oblique slice is kept: $LUCENT_CACHE_DIR, else $XDG_CACHE_HOME/lucent, else
/// $HOME/.cache/lucent (empty when none is set).
std::filesystem::path oblique_cache_dir();

}  // namespace lucent::materials
