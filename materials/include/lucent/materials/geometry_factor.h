// How the shape of an object changes multiple scattering between two surface points (lucent;
// docs/DESIGN.md §4.4). The radial BSSRDFs (tabulated, dipole) are profiles of a plane: R(r) for
// light entering and leaving one flat face r apart. On a curved object the exit point is off the
// entry point's plane, and on the far side of a thin one the light crosses the exit surface along
// the direction it diffuses in, where on a plane it leaves sideways. Diffusion theory says how much
// that matters: a dipole (a source z_r inside, its negative image z_v outside) has a fluence phi
// everywhere, and the flux leaving through a surface at x_o with outward normal n_o is
//   J = -D grad(phi)(x_o) . n_o = alpha' / (4 pi) sum_k sign_k f(d_k) (x_o - x_k) . n_o,
//   f(d) = (1 + sigma_tr d) e^(-sigma_tr d) / d^3,
// which is the dipole's own R_d(r) when x_o lies on the dipole's plane with n_o its normal. The
// factor G = J / R_d(|x_o - x_i|) carries the shape over to any radial profile (the tabulated
// transport table included), and is exactly 1 on a plane, where the table is exact. Two placements
// of the dipole, blended by how far the exit faces away from the entry (w = max(0, -n_i . n_o)):
//  - tangent (Frisvad et al. 2014's modified tangent plane): the plane through x_i that contains
//    x_o, its normal n* = n_i less its component along x_o - x_i. The images stay as far from x_o
//    as on a plane; what remains is the exit normal's tilt: G_t = n* . n_o + (x . n_o) (f_r - f_v)
//    / (z_r f_r + z_v f_v), x = x_o - x_i, d_k = sqrt(r^2 + z_k^2). Convex surfaces a little
//    above 1.
//  - through (x_i's own plane): light crossing a slab or a sphere to the far side, which the
//    tangent plane cannot place (x_o - x_i along n_i): the dipole's flux through n_o at x_o, plus
//    the same 2 z_b = 4 A D further out (an image about the exit's extrapolated plane: the entry
//    dipole alone does not make the fluence vanish beyond the exit; where exit and entry share a
//    plane it does, and w = 0 there).
// G = sqrt(g(i -> o) g(o -> i)) (reciprocal), g = (1 - w) G_t + w G_through, each clamped to
// [0, kMax].
// Measured against the path tracer (64 px spheres of 10-100 mm, the reference with the tabulated
// model; docs/DESIGN.md §4.4): front-lit channel means 0.87-1.00 -> 0.99-1.07 at eta 1.3-1.5;
// lit from behind 0.32-0.66 -> 0.44-0.90 (still short: see there).
#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "lucent/materials/material.h"
#include "lucent/materials/medium.h"
#include "lucent/materials/profile_table.h"

namespace lucent::materials {

/// Whether the factor applies to `model`: the radial models (tabulated, dipole); the directional
/// dipole places its own sources with both normals.
inline bool geometry_factor_applies(DiffusionModel model) {
  return model != DiffusionModel::kDirectionalDipole;
}

template <typename T>
class GeometryFactor {
 public:
  using Vec3 = Eigen::Matrix<T, 3, 1>;
  /// The largest factor taken (so that a mesh's folds and seams cannot make a firefly): the far
  /// side of a slab d thick is ~(sigma_tr d)^2 / (1 + sigma_tr d) above the plane's R_d(d).
  static constexpr double kMax = 64;

  explicit GeometryFactor(const DiffusionCoefficients<T>& c) : c_(c) {}

  /// G for light entering at x_i (outward unit normal n_i) and leaving at x_o (n_o), mm.
  T operator()(const Vec3& x_i, const Vec3& n_i, const Vec3& x_o, const Vec3& n_o) const {
    using std::sqrt;
    if (!c_.scatters()) return T(1);
    return sqrt(one_way(x_i, n_i, x_o, n_o) * one_way(x_o, n_o, x_i, n_i));
  }

  /// g from x_i to x_o only (not reciprocal).
  T one_way(const Vec3& x_i, const Vec3& n_i, const Vec3& x_o, const Vec3& n_o) const {
    using std::sqrt;
    const Vec3 x = x_o - x_i;
    const T r2 = x.squaredNorm();
    if (!(r2 > T(1e-12) * c_.z_r * c_.z_r)) return T(1);
    const T s0 = c_.sigma_tr * sqrt(r2);  // e^(-s0): the scale J and R_d share, left out of both
    const T f_r = term(r2 + c_.z_r * c_.z_r, s0), f_v = term(r2 + c_.z_v * c_.z_v, s0);
    const T planar = c_.z_r * f_r + c_.z_v * f_v;
    if (!(planar > T(0))) return T(1);
    const T along = x.dot(n_o);
    // Tangent: n* = n_i less its component along x (n_i itself where x runs along n_i).
    Vec3 n_star = n_i - (n_i.dot(x) / r2) * x;
    const T length = n_star.norm();
    n_star = length > T(1e-6) ? Vec3(n_star / length) : n_i;
    const T tangent = std::clamp(n_star.dot(n_o) + along * (f_r - f_v) / planar, T(0), T(kMax));
    const T w = std::clamp(-n_i.dot(n_o), T(0), T(1));
    if (!(w > T(0))) return tangent;
    // Through: the sources at x_i -/+ z n_i; the exit's own boundary condition (the fluence 0 at
    // its extrapolated plane, 2 A D beyond x_o) adds the flux the dipole has 2 z_b further out.
    const T z_b = T(0.5) * (c_.z_v - c_.z_r);
    auto flux = [&](const Vec3& p) {
      const Vec3 a = p - (x_i - c_.z_r * n_i), b = p - (x_i + c_.z_v * n_i);
      return term(a.squaredNorm(), s0) * a.dot(n_o) - term(b.squaredNorm(), s0) * b.dot(n_o);
    };
    const T through = (flux(x_o) + flux(x_o + T(2) * z_b * n_o)) / planar;
    return (T(1) - w) * tangent + w * std::clamp(through, T(0), T(kMax));
  }

 private:
  // f(d) e^(s0) = (1 + s) e^(s0 - s) / d^3 with s = sigma_tr d.
  T term(T d2, T s0) const {
    using std::exp;
    using std::sqrt;
    const T d = sqrt(std::max(d2, T(1e-20)));
    const T s = c_.sigma_tr * d;
    return (T(1) + s) * exp(s0 - s) / (d2 * d);
  }

  DiffusionCoefficients<T> c_;
};

}  // namespace lucent::materials
