// The directional dipole of Frisvad, Hachisuka and Kjeldsen 2014 (Dal Corso 2014 §3.4.8, Appendix
// B), in the formulation of the authors' sample code as docs/DESIGN.md §4.1 spells it out. The
// thesis writes e^(+sigma_tr r) in eqs. 3.7 and 3.10; the exponent is negative.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <string>

#include "lucent/materials/medium.h"

namespace lucent::materials {

template <typename T>
using Vec3 = Eigen::Matrix<T, 3, 1>;

template <typename T>
class DirectionalDipole {
 public:
  explicit DirectionalDipole(const Medium<T>& medium)
      : medium_(medium), c_(derive_coefficients(medium)) {}

  /// S_d(x_i, n_i, w_i, x_o, n_o) per mm^2 per sr for unit incident flux, without the two Fresnel
  /// transmittances, clamped at 0. Positions in mm; n_i, n_o outward unit normals; w_i the unit
  /// direction from x_i toward the light (w_i . n_i > 0 when front-lit).
  T S_d(const Vec3<T>& x_i, const Vec3<T>& n_i, const Vec3<T>& w_i, const Vec3<T>& x_o,
        const Vec3<T>& n_o) const {
    using std::sqrt;
    if (!c_.scatters()) return T(0);  // d_e divides by sqrt(alpha')
    const Vec3<T> x = x_o - x_i;
    const T r2 = x.squaredNorm();
    const T r = safe_sqrt(r2);

    // Modified tangent-plane normal n_i* = (x / r) x normalize(n_i x x); n_i itself where that is
    // undefined (x_o = x_i, or x along n_i).
    Vec3<T> n_star = n_i;
    // x . n_i*: exactly 0 when n_i* is the modified normal (perpendicular to x by construction);
    // taken as 0 rather than computed, whose rounding (eps r) would swamp the virtual source's
    // offset a^2 - 2 a (x . n_i*) at r of thousands of mean free paths.
    T x_n = x.dot(n_i);
    const Vec3<T> nx = n_i.cross(x);
    const T nx2 = nx.squaredNorm();
    if (r2 > T(0) && nx2 > T(1e-24) * r2) {
      n_star = (x / r).cross(nx / sqrt(nx2));
      x_n = T(0);
    }

    // Refracted direction of the real source (Snell with relative index 1/eta). Beyond the critical
    // angle (eta < 1) no light enters and the Fresnel transmittance is 0; the radicand is clamped
    // at 0 so S_d stays finite and continuous there.
    const T cos_i = w_i.dot(n_i);
    const T inv_eta = T(1) / c_.eta;
    T radicand = T(1) - (T(1) - cos_i * cos_i) * inv_eta * inv_eta;
    if (radicand < T(0)) radicand = T(0);
    const Vec3<T> w_r =
        (-w_i * inv_eta - n_i * (-cos_i * inv_eta + safe_sqrt(radicand))).normalized();
    const Vec3<T> w_v = w_r - T(2) * w_r.dot(n_star) * n_star;

    // Distance to the real source: front-lit points see it through the extrapolated boundary,
    // back-lit ones at one unreduced mean free path below the surface. Both are kept as offsets
    // from r^2 (d_r^2 = r^2 + real_offset) so that the real-minus-virtual difference below never
    // subtracts two nearly equal r^2.
    const T mu0 = -n_o.dot(w_r);
    T real_offset;
    if (mu0 > T(0)) {
      // r^2 - (x . w_r)^2 = |x cross w_r|^2, which has no cancellation when x is nearly along w_r.
      const T across2 = x.cross(w_r).squaredNorm();
      const T cos_beta = across2 > T(0) ? -sqrt(across2 / (r2 + c_.d_e * c_.d_e)) : T(0);
      const T D_mu0 = c_.D * mu0;
      real_offset = D_mu0 * (D_mu0 - T(2) * c_.d_e * cos_beta);
    } else {
      const T inv = T(1) / (T(3) * c_.sigma_t);
      real_offset = inv * inv;
    }

    // Virtual source x_v = x_i + a n_i*, a = 2 A d_e; from it x_o - x_v = x - a n_i*, so
    // d_v^2 = r^2 + a^2 - 2 a (x . n_i*), again as an offset from r^2.
    const T a = T(2) * c_.A_ddipole * c_.d_e;
    const Vec3<T> x_ov = x - a * n_star;
    T virtual_offset = a * a - T(2) * a * x_n;
    // The virtual source lies outside the medium, 2 A d_e from x_i; only a configuration with x_o
    // off the surface can come near it. Keep its distance positive there so the result stays
    // finite.
    const T min_d2 = T(1e-12) * c_.d_e * c_.d_e;
    if (r2 + virtual_offset < min_d2) virtual_offset = min_d2 - r2;

    return difference_of_sources(x, w_r, r2 + real_offset, x_ov, w_v, r2 + virtual_offset,
                                 virtual_offset - real_offset, a, T(2) * w_r.dot(n_star), x_n,
                                 n_star, n_o);
  }

  const Medium<T>& medium() const { return medium_; }
  const DiffusionCoefficients<T>& coefficients() const { return c_; }
  std::string to_string() const { return "DirectionalDipole{" + c_.to_string() + "}"; }

 private:
  // sqrt with a finite derivative at 0 for ceres::Jet (d sqrt / dx is infinite there; positions
  // carry no derivative, so 0 is the right value).
  static T safe_sqrt(T v) {
    using std::sqrt;
    return v > T(0) ? sqrt(v) : T(0);
  }

  // S'(x, w_r, d_r) - S'(x_v, w_v, d_v), clamped at 0, where one ray source's profile is
  //   S'(y, w, d) = N / (4 pi^2) e^(-sigma_tr d) / d^3 B(d, y, w),
  //   B = C_phi (d^2 / D + 3 u (y.w)) - C_E (3 D u (w.n_o) - (u + 3 D (3 u + s^2) (y.w) / d^2)
  //   (y.n_o)), s = sigma_tr d, u = 1 + s.
  // Far from the source (r of hundreds of mean free paths at albedo near 1) the two profiles agree
  // to many digits and their plain difference loses them all, in float above all. So the difference
  // is taken algebraically: with F = e^(-sigma_tr (d_v - d_r)) (d_r / d_v)^3,
  //   S = N / (4 pi^2) e^(-sigma_tr d_r) / d_r^3 [ (B_r - B_v) + B_v (1 - F) ],
  // 1 - F through expm1/log1p, and B_r - B_v term by term from the exact differences of its parts:
  //   d_v^2 - d_r^2 = delta2 (no r^2 in it), (y.w)_r - (y.w)_v = b (x.n*) - a (w_r.n*),
  //   (w.n_o)_r - (w.n_o)_v = b (n*.n_o), (y.n_o)_r - (y.n_o)_v = a (n*.n_o),
  // where x_v = x - a n*, w_v = w_r - b n*. Algebraically identical to the authors' form (the
  // golden test holds the two together to 1e-10). Where the virtual source is much the weaker (F <
  // 1/2, as at low albedo, where it sits far above the surface) the plain B_r - B_v F is the better
  // form.
  T difference_of_sources(const Vec3<T>& x, const Vec3<T>& w_r, T d_r2, const Vec3<T>& x_ov,
                          const Vec3<T>& w_v, T d_v2, T delta2, T a, T b, T x_n,
                          const Vec3<T>& n_star, const Vec3<T>& n_o) const {
    using std::exp;
    using std::expm1;
    using std::log;
    using std::log1p;
    using std::sqrt;
    const T sigma = c_.sigma_tr;
    const T D = c_.D;
    const T d_r = sqrt(d_r2);
    const T d_v = sqrt(d_v2);
    const T dd = -delta2 / (d_r + d_v);  // d_r - d_v

    // Parts of B at the virtual source, and their real-minus-virtual differences.
    const T s_v = sigma * d_v;
    const T u_v = T(1) + s_v;
    const T yw_v = x_ov.dot(w_v), wn_v = w_v.dot(n_o), yn_v = x_ov.dot(n_o);
    const T q_v = T(1) / d_v2;
    const T H_v = T(3) * u_v + s_v * s_v;
    const T G_v = u_v + T(3) * D * H_v * q_v * yw_v;
    const T B_v =
        c_.C_phi * (d_v2 / D + T(3) * u_v * yw_v) - c_.C_E * (T(3) * D * u_v * wn_v - G_v * yn_v);

    const T s_r = sigma * d_r;
    const T u_r = T(1) + s_r;
    const T q_r = T(1) / d_r2;
    const T H_r = T(3) * u_r + s_r * s_r;

    // F = e^(-sigma (d_v - d_r)) (d_r / d_v)^3; log F and 1 - F without cancellation.
    const T log_F = sigma * dd - T(1.5) * log1p(delta2 * q_r);
    T bracket;
    if (log_F < T(-0.7)) {
      // The virtual source is far weaker than the real one (F < 1/2): the plain difference is
      // well conditioned, and the term-by-term one would subtract large parts of B_v instead.
      const T yw_r = x.dot(w_r), wn_r = w_r.dot(n_o), yn_r = x.dot(n_o);
      const T G_r = u_r + T(3) * D * H_r * q_r * yw_r;
      const T B_r =
          c_.C_phi * (d_r2 / D + T(3) * u_r * yw_r) - c_.C_E * (T(3) * D * u_r * wn_r - G_r * yn_r);
      bracket = B_r - B_v * exp(log_F);
    } else {
      const T d_u = sigma * dd;                           // u_r - u_v
      const T d_yw = b * x_n - a * w_r.dot(n_star);       // (y.w)_r - (y.w)_v
      const T d_wn = b * n_star.dot(n_o);                 // (w.n_o)_r - (w.n_o)_v
      const T d_yn = a * n_star.dot(n_o);                 // (y.n_o)_r - (y.n_o)_v
      const T d_q = delta2 * q_r * q_v;                   // 1/d_r^2 - 1/d_v^2
      const T d_H = T(3) * d_u - sigma * sigma * delta2;  // H_r - H_v
      const T d_G = d_u + T(3) * D * (H_r * q_r * d_yw + H_r * d_q * yw_v + d_H * q_v * yw_v);
      const T G_r = G_v + d_G;
      const T d_B = c_.C_phi * (-delta2 / D + T(3) * (u_r * d_yw + d_u * yw_v)) -
                    c_.C_E * (T(3) * D * (u_r * d_wn + d_u * wn_v) - (G_r * d_yn + d_G * yn_v));
      bracket = d_B - B_v * expm1(log_F);
    }
    const T prefactor = c_.normalisation / T(4 * std::numbers::pi * std::numbers::pi) *
                        exp(-s_r - T(1.5) * log(d_r2));
    const T S = prefactor * bracket;
    return S > T(0) ? S : T(0);
  }

  Medium<T> medium_;
  DiffusionCoefficients<T> c_;
};

}  // namespace lucent::materials
