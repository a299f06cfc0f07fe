// The tabulated model (docs/DESIGN.md §4.2): a transport table interpolated C1-smoothly in log
// value over log radius, u = sqrt(1 - alpha') and eta, templated on the scalar so that ceres::Jet
// carries exact derivatives of the interpolant through a fit.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "lucent/materials/fresnel.h"
#include "lucent/materials/medium.h"
#include "lucent/materials/transport_table.h"

namespace lucent::materials {

/// Cubic Hermite weights of the (up to) four nodes around t: the tangent at each node is the
/// distance-weighted mean of its two neighbouring slopes (Catmull-Rom on a nonuniform grid), one-
/// sided at the ends, so the interpolant is C1. Outside [nodes.front(), nodes.back()], linear
/// extrapolation from the end cell (extrapolate) or the end value (clamp).
template <typename T>
struct NodeWeights {
  int first = 0;  ///< index of w[0]'s node
  int count = 0;
  std::array<T, 4> w{};
};

template <typename T>
NodeWeights<T> hermite_weights(const std::vector<double>& x, const T& t, bool extrapolate) {
  NodeWeights<T> r;
  const int n = int(x.size());
  if (n == 1) {
    r.count = 1;
    r.w[0] = T(1);
    return r;
  }
  if (!(t > T(x.front())) || !(t < T(x.back()))) {
    const bool low = !(t > T(x.front()));
    const int i = low ? 0 : n - 2;
    r.first = i;
    r.count = 2;
    if (!extrapolate) {
      r.w[low ? 0 : 1] = T(1);
      r.w[low ? 1 : 0] = T(0);
      return r;
    }
    const T s = (t - T(x[i])) / T(x[i + 1] - x[i]);
    r.w[0] = T(1) - s;
    r.w[1] = s;
    return r;
  }
  int i = 0, hi = n - 1;  // x[i] <= t < x[i + 1]
  while (hi - i > 1) {
    const int mid = (i + hi) / 2;
    if (t < T(x[mid]))
      hi = mid;
    else
      i = mid;
  }
  const double h = x[i + 1] - x[i];
  const T s = (t - T(x[i])) / T(h);
  const T s2 = s * s, s3 = s2 * s;
  const T h00 = T(2) * s3 - T(3) * s2 + T(1), h10 = s3 - T(2) * s2 + s;
  const T h01 = T(-2) * s3 + T(3) * s2, h11 = s3 - s2;
  // Weights on f[i-1], f[i], f[i+1], f[i+2].
  std::array<T, 4> w{T(0), h00, h01, T(0)};
  // Tangent at i (times h): on f[i-1], f[i], f[i+1].
  if (i == 0) {
    w[1] -= h10;
    w[2] += h10;
  } else {
    const double hp = x[i] - x[i - 1];
    const double a = hp / (hp + h);  // weight of the right slope
    w[2] += h10 * T(a);
    w[1] -= h10 * T(a);
    w[1] += h10 * T((1 - a) * h / hp);
    w[0] -= h10 * T((1 - a) * h / hp);
  }
  // Tangent at i + 1 (times h): on f[i], f[i+1], f[i+2].
  if (i + 1 == n - 1) {
    w[2] += h11;
    w[1] -= h11;
  } else {
    const double hn = x[i + 2] - x[i + 1];
    const double a = h / (h + hn);  // weight of the right slope
    w[3] += h11 * T(a * h / hn);
    w[2] -= h11 * T(a * h / hn);
    w[2] += h11 * T(1 - a);
    w[1] -= h11 * T(1 - a);
  }
  if (i == 0) {
    r.first = 0;
    r.count = 3;
    r.w = {w[1], w[2], w[3], T(0)};
    if (i + 1 == n - 1) r.count = 2;
  } else {
    r.first = i - 1;
    r.count = i + 1 == n - 1 ? 3 : 4;
    r.w = w;
  }
  return r;
}

/// The value of a scalar or of a Jet's real part (for choosing a cell; never differentiated).
inline double scalar_of(double v) { return v; }
inline double scalar_of(float v) { return v; }
template <typename T>
double scalar_of(const T& v) {
  return v.a;
}

/// hermite_weights for nodes x0 + i h, i < n (n >= 3): the cell found by arithmetic instead of a
/// search, the tangents central differences (what the general rule gives on uniform nodes).
template <typename T>
NodeWeights<T> uniform_hermite_weights(double x0, double h, int n, const T& t) {
  NodeWeights<T> r;
  const double pos = (scalar_of(t) - x0) / h;
  if (!(pos > 0) || !(pos < n - 1)) {  // outside: linear from the end cell
    const int i = pos > 0 ? n - 2 : 0;
    const T s = (t - T(x0 + i * h)) / T(h);
    r.first = i, r.count = 2, r.w[0] = T(1) - s, r.w[1] = s;
    return r;
  }
  const int i = std::min(int(pos), n - 2);
  const T s = (t - T(x0 + i * h)) / T(h);
  const T s2 = s * s, s3 = s2 * s;
  const T h00 = T(2) * s3 - T(3) * s2 + T(1), h10 = s3 - T(2) * s2 + s;
  const T h01 = T(-2) * s3 + T(3) * s2, h11 = s3 - s2;
  const T half(0.5);
  if (i == 0) {
    r.first = 0, r.count = 3;
    r.w = {h00 - h10 - half * h11, h01 + h10, half * h11, T(0)};
  } else if (i + 1 == n - 1) {
    r.first = i - 1, r.count = 3;
    r.w = {-half * h10, h00 - h11, h01 + half * h10 + h11, T(0)};
  } else {
    r.first = i - 1, r.count = 4;
    r.w = {-half * h10, h00 - half * h11, h01 + half * h10, half * h11};
  }
  return r;
}

/// A row of log values over uniform nodes x (ln rho of the bin centres) at rho: Hermite inside,
/// linear in ln rho below the first centre, linear in rho beyond the last (falling only: beyond
/// the table a profile cannot rise).
template <typename T>
T interpolate_row(const std::vector<double>& x, const T* row, const T& rho) {
  using std::log;
  const std::size_t J = x.size();
  const T lr = log(rho);
  if (lr > T(x.back())) {
    T slope = (row[J - 1] - row[J - 2]) / T(x[J - 1] - x[J - 2]);
    if (slope > T(0)) slope = T(0);
    return row[J - 1] + slope * (rho / T(std::exp(x.back())) - T(1));
  }
  const NodeWeights<T> w = uniform_hermite_weights(x.front(), x[1] - x[0], int(J), lr);
  T sum(0);
  for (int c = 0; c < w.count; ++c) sum += w.w[std::size_t(c)] * row[std::size_t(w.first + c)];
  return sum;
}
template <typename T>
T interpolate_row(const std::vector<double>& x, const std::vector<T>& row, const T& rho) {
  return interpolate_row(x, row.data(), rho);
}

namespace detail {
/// Annulus averages of a row of logs over the grid's radius bins -> point values at the bins'
/// log centres x (in place).
void to_point_values(std::vector<double>& f, const std::vector<double>& x,
                     const TransportTableGrid& grid);
}  // namespace detail

class ObliqueProfile;
class TabulatedProfile;

/// A slab's profiles at one (eta, g), one per thickness node (d sigma_s', ascending; lucent fit
/// --thickness-mm builds and caches them): the lit side's and the far side's. The lit side's list
/// ends with the semi-infinite profile, placed at 4 times the thickest slab (beyond it the lit side
/// is the semi-infinite sample's within the table's reach).
struct SlabNodes {
  std::vector<double> log_thickness_s;             ///< ln(d sigma_s') of reflected's nodes
  std::vector<TabulatedProfile> reflected;          ///< one eta each
  std::vector<double> log_thickness_s_transmitted;  ///< ln(d sigma_s') of transmitted's nodes
  std::vector<TabulatedProfile> transmitted;
  std::string source;  ///< for messages: where the nodes came from
};

/// A transport table at one g, ready to evaluate: log(value / alpha') at the point centres of the
/// radius bins (the annulus averages of the file turned into point values by a second-order
/// correction), per eta slice.
class TabulatedProfile {
 public:
  /// The slices of `table` at anisotropy g: a g node, or C1 interpolation between g nodes (every g
  /// node must have the same eta slices). Throws lucent::Error when g is outside the table.
  TabulatedProfile(const TransportTable& table, double g);
  /// A slab table's slices (TransportTable::slab()), for SlabNodes; the constructor above refuses
  /// them.
  static TabulatedProfile slab_node(const TransportTable& table, double g);
  /// The same profile with eta fixed (one slice: faster when eta is not fitted).
  TabulatedProfile at_eta(double eta) const;
  /// A copy with every measured entry's log value moved by a normal draw of its relative standard
  /// error (seeded): one realisation of the table's Monte Carlo noise, for propagating it into a
  /// fit by a parametric bootstrap.
  TabulatedProfile perturbed(std::uint64_t seed) const;
  /// A copy carrying an oblique slice (oblique.h) for 2D data at that incidence: the fit uses it
  /// in place of the corrected directional dipole (and perturbs it with the rest).
  TabulatedProfile with_oblique(std::shared_ptr<const ObliqueProfile> oblique) const;
  const ObliqueProfile* oblique() const { return oblique_.get(); }
  /// A copy carrying a slab's profiles at its eta and g: TabulatedModel evaluates a slab of a given
  /// thickness and side from them (and perturbed() perturbs them with the rest).
  TabulatedProfile with_slab(std::shared_ptr<const SlabNodes> slab) const;
  const SlabNodes* slab() const { return slab_.get(); }

  double g() const { return g_; }
  double eta_min() const { return eta_.front(); }
  double eta_max() const { return eta_.back(); }
  const std::vector<double>& eta_nodes() const { return eta_; }
  double u_max() const { return u_.back(); }
  double rho_min() const { return rho_min_; }
  double rho_max() const { return rho_max_; }
  /// ln rho of the bin centres: the uniform nodes the rows of rows_at are given on.
  const std::vector<double>& log_rho_nodes() const { return x_; }
  std::uint64_t photons() const { return photons_; }
  std::string to_string() const;

  /// log(value / (sigma_t'^2 alpha')) at rho = r sigma_t', u = sqrt(1 - alpha'), eta (clamped to
  /// the table's range; u clamped to its last node, so below the table's smallest albedo the
  /// value scales as alpha').
  template <typename T>
  T log_value(TableQuantity q, const T& rho, const T& u, const T& eta) const {
    std::array<std::vector<T>, kTableQuantities> rows;
    rows_at(u, eta, rows);
    return row_log_value(rows[std::size_t(q)], rho);
  }

  /// The rows of log(value / alpha') over the bin centres at (u, eta), both quantities: what a
  /// model of fixed coefficients evaluates at many radii (combined once, then one 1D
  /// interpolation per radius).
  template <typename T>
  void rows_at(const T& u, const T& eta, std::array<std::vector<T>, kTableQuantities>& rows) const {
    const NodeWeights<T> we = hermite_weights(eta_, eta, false);
    const T uc = u < T(u_.back()) ? u : T(u_.back());
    const NodeWeights<T> wu = hermite_weights(u_, uc, false);
    for (int q = 0; q < kTableQuantities; ++q) {
      std::vector<T>& row = rows[std::size_t(q)];
      row.assign(std::size_t(J_), T(0));
      for (int a = 0; a < we.count; ++a) {
        const std::vector<double>& f = f_[std::size_t(we.first + a)][std::size_t(q)];
        for (int b = 0; b < wu.count; ++b) {
          const T w = we.w[std::size_t(a)] * wu.w[std::size_t(b)];
          const double* src = f.data() + std::size_t(wu.first + b) * std::size_t(J_);
          for (int j = 0; j < J_; ++j) row[std::size_t(j)] += w * T(src[j]);
        }
      }
    }
  }

  /// A row from rows_at evaluated at rho (interpolate_row).
  template <typename T>
  T row_log_value(const std::vector<T>& row, const T& rho) const {
    return interpolate_row(x_, row, rho);
  }

  /// value / sigma_t'^2 (exitance R, or pi L along the normal), per unit power entering.
  template <typename T>
  T value(TableQuantity q, const T& rho, const T& alpha_prime, const T& eta) const {
    using std::exp;
    using std::sqrt;
    const T one_minus = T(1) - alpha_prime;
    const T u = one_minus > T(0) ? sqrt(one_minus) : T(0);
    return alpha_prime * exp(log_value(q, rho, u, eta));
  }

  /// Total diffuse reflectance per unit power entering.
  template <typename T>
  T total(const T& alpha_prime, const T& eta) const {
    using std::exp;
    using std::sqrt;
    const T one_minus = T(1) - alpha_prime;
    T u = one_minus > T(0) ? sqrt(one_minus) : T(0);
    if (!(u < T(u_.back()))) u = T(u_.back());
    const NodeWeights<T> we = hermite_weights(eta_, eta, false);
    const NodeWeights<T> wu = hermite_weights(u_, u, false);
    T sum(0);
    for (int a = 0; a < we.count; ++a)
      for (int b = 0; b < wu.count; ++b)
        sum += we.w[a] * wu.w[b] * T(log_total_[std::size_t(we.first + a)][std::size_t(wu.first + b)]);
    return alpha_prime * exp(sum);
  }

  /// The table's relative standard error near (rho, alpha', eta) (the largest of the entries the
  /// interpolation leans on most); infinity in an extrapolated tail.
  double relative_se(TableQuantity q, double rho, double alpha_prime, double eta) const;
  /// The same for a slab of d sigma_s' = thickness_s seen from one side (SlabNodes): the larger of
  /// the two thickness nodes around it (this profile's own where it has no slab nodes, or
  /// thickness_s is infinite).
  double relative_se(TableQuantity q, double rho, double alpha_prime, double eta,
                     double thickness_s, bool transmitted) const;
  /// The relative standard error of the table's total diffuse reflectance at the nearest nodes.
  double total_relative_se(double alpha_prime, double eta) const;

 private:
  TabulatedProfile() = default;
  double g_ = 0;
  std::vector<double> eta_, u_, x_;  // x = ln(rho) of the bin centres
  int J_ = 0;
  double rho_min_ = 0, rho_max_ = 0;
  std::uint64_t photons_ = 0;
  // [slice][quantity][k * J + j]
  std::vector<std::array<std::vector<double>, kTableQuantities>> f_;
  std::vector<std::array<std::vector<float>, kTableQuantities>> rel_se_;
  std::vector<std::vector<double>> log_total_;  // [slice][k]: log(total / alpha')
  std::vector<std::vector<double>> total_rel_se_;  // [slice][k]
  std::shared_ptr<const ObliqueProfile> oblique_;
  std::shared_ptr<const SlabNodes> slab_;
};

/// A prepared profile of `table` at g (and, when given, at a fixed eta), made once per (table, g,
/// eta) and kept for the process: preparing one costs ~0.1 s (the annulus-average
/// deconvolution), evaluating it microseconds. Thread-safe. Throws like the constructor.
std::shared_ptr<const TabulatedProfile> cached_tabulated_profile(const TransportTable& table,
                                                                 double g,
                                                                 std::optional<double> eta = {});

/// The tabulated model of one channel, in the shape of the other models: lengths in mm.
template <typename T>
class TabulatedModel {
 public:
  /// The profile's g is the medium's anisotropy (the medium's own g is not used: sigma_s' is).
  /// thickness_mm finite: a slab of that thickness (the profile must carry SlabNodes), its lit side
  /// or, with `transmitted`, its far side; interpolated C1 in ln(d sigma_s') between the nodes.
  TabulatedModel(const TabulatedProfile& profile, const Medium<T>& m,
                 double thickness_mm = std::numeric_limits<double>::infinity(),
                 bool transmitted = false)
      : profile_(&profile), eta_(m.eta) {
    using std::sqrt;
    sigma_t_reduced_ = m.sigma_a + m.sigma_s * (T(1) - m.g);
    alpha_prime_ = sigma_t_reduced_ > T(0) ? m.sigma_s * (T(1) - m.g) / sigma_t_reduced_ : T(0);
    if (alpha_prime_ > T(0)) {
      const T one_minus = T(1) - alpha_prime_;
      const T u = one_minus > T(0) ? sqrt(one_minus) : T(0);
      const SlabNodes* slab = profile.slab();
      if (slab && thickness_mm < std::numeric_limits<double>::infinity()) {
        using std::log;
        const std::vector<double>& x =
            transmitted ? slab->log_thickness_s_transmitted : slab->log_thickness_s;
        const std::vector<TabulatedProfile>& nodes = transmitted ? slab->transmitted : slab->reflected;
        // d sigma_s' = d alpha' sigma_t'; clamped to the nodes' range.
        const NodeWeights<T> w =
            hermite_weights(x, log(T(thickness_mm) * alpha_prime_ * sigma_t_reduced_), false);
        std::array<std::vector<T>, kTableQuantities> node_rows;
        for (int k = 0; k < w.count; ++k) {
          nodes[std::size_t(w.first + k)].rows_at(u, eta_, node_rows);
          for (int q = 0; q < kTableQuantities; ++q) {
            std::vector<T>& row = rows_[std::size_t(q)];
            if (row.empty()) row.assign(node_rows[std::size_t(q)].size(), T(0));
            for (std::size_t j = 0; j < row.size(); ++j)
              row[j] += w.w[std::size_t(k)] * node_rows[std::size_t(q)][j];
          }
        }
      } else {
        profile.rows_at(u, eta_, rows_);
      }
      scale_ = sigma_t_reduced_ * sigma_t_reduced_ * alpha_prime_;
      // Beyond the table: the standard dipole's fall-off in optical units (sigma_t' = 1).
      const DiffusionCoefficients<T> c =
          derive_coefficients(Medium<T>{T(1) - alpha_prime_, alpha_prime_, T(0), eta_});
      far_sigma_tr_ = c.sigma_tr, far_z_r_ = c.z_r, far_z_v_ = c.z_v;
      rho_edge_ = std::exp(profile.log_rho_nodes().back());
      far_log_edge_ = far_log_dipole(T(rho_edge_));
    }
  }

  /// Radial exitance R(r) per mm^2 per unit power entering.
  T R_d(T r_mm) const { return at(TableQuantity::kExitance, r_mm); }
  /// pi L(r) along the normal per mm^2 per unit power entering.
  T radiance(T r_mm) const { return at(TableQuantity::kRadiance, r_mm); }
  /// Beyond the table's last radius (rho ~90-100: 12-45 mm for milk, cream and marble, where
  /// captures still have signal and sigma_a shows) the table's last value carried by the standard
  /// dipole's fall-off: there, tens of mean free paths out, diffusion is exact in shape (its
  /// decay rate sqrt(3 (1 - alpha')) differs from transport's by O(1 - alpha')), while the row's
  /// own linear extrapolation follows the noisy slope of the last bins (at alpha' 0.9999, 24-81%
  /// high at rho 110-200 against a table that reaches further; this, 5-14% within that table's
  /// 7-13% noise: tabulate_test). S_d (the renderers and their GLSL twin) keeps the row's.
  T at(TableQuantity q, T r_mm) const {
    if (!(alpha_prime_ > T(0))) return T(0);
    const T rho = r_mm * sigma_t_reduced_;
    const T floor(1e-12);  // r = 0: the innermost bin's power law would diverge
    using std::exp;
    const std::vector<T>& row = rows_[std::size_t(q)];
    if (rho > T(rho_edge_)) return scale_ * exp(row.back() + far_log_dipole(rho) - far_log_edge_);
    return scale_ * exp(profile_->row_log_value(row, rho > floor ? rho : floor));
  }
  /// S_d per mm^2 per sr without the two Fresnel transmittances, as the renderers use the model
  /// (docs/DESIGN.md §4.2): pi L along the normal / (pi F_t(eta, 1)), so that times the outgoing
  /// F_t it is the table's radiance along the normal (`lucent profile --quantity radiance`).
  T S_d(T r_mm) const {
    if (!(alpha_prime_ > T(0))) return T(0);
    const T rho = r_mm * sigma_t_reduced_;
    const T floor(1e-12);
    using std::exp;
    return S_d_scale() *
           exp(profile_->row_log_value(rows_[std::size_t(TableQuantity::kRadiance)],
                                       rho > floor ? rho : floor));
  }
  /// S_d = S_d_scale() e^(row(ln rho)) with row = log_row(kRadiance): what the GLSL twin uploads.
  T S_d_scale() const {
    return scale_ / (T(std::numbers::pi) * fresnel_transmittance(T(1), eta_));
  }
  /// The model's row of log(value / (sigma_t'^2 alpha')) over TabulatedProfile::log_rho_nodes().
  const std::vector<T>& log_row(TableQuantity q) const { return rows_[std::size_t(q)]; }
  T total_diffuse_reflectance() const {
    if (!(alpha_prime_ > T(0))) return T(0);
    return profile_->total(alpha_prime_, eta_);
  }
  const T& alpha_prime() const { return alpha_prime_; }
  const T& sigma_t_reduced() const { return sigma_t_reduced_; }

 private:
  // log of the standard dipole's R_d at rho in optical units, up to a constant, from logs of its
  // two sources (no under- or overflow however far out, so Jets stay finite).
  T far_log_dipole(const T& rho) const {
    using std::exp;
    using std::log;
    using std::sqrt;
    const auto log_source = [&](const T& z) {
      const T d = sqrt(rho * rho + z * z);
      return log(z) + log(T(1) + far_sigma_tr_ * d) - far_sigma_tr_ * d - T(3) * log(d);
    };
    const T a = log_source(far_z_r_), b = log_source(far_z_v_);
    const T hi = a > b ? a : b, lo = a > b ? b : a;
    return hi + log(T(1) + exp(lo - hi));
  }

  const TabulatedProfile* profile_;
  T eta_, sigma_t_reduced_, alpha_prime_, scale_{0};
  std::array<std::vector<T>, kTableQuantities> rows_;
  double rho_edge_ = 0;  // the last bin centre: the row's last node
  T far_sigma_tr_{0}, far_z_r_{1}, far_z_v_{1}, far_log_edge_{0};
};

}  // namespace lucent::materials
