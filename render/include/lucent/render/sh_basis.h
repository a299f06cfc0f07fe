// Real spherical harmonics of bands 0-4 (25 functions) for the fur technique's precomputed radiance
// transfer (Klotzli & Olano, Klotzli and Olano, eqs. 5-7), templated on the scalar.
//
//   Y_l^m = sqrt(2) K_l^m  cos(m phi)  P_l^m(cos theta),      m > 0
//   Y_l^m = sqrt(2) K_l^|m| sin(|m| phi) P_l^|m|(cos theta),  m < 0
//   Y_l^0 = K_l^0 P_l^0(cos theta),   K_l^m = sqrt((2l + 1) / 4 pi  (l - |m|)! / (l + |m|)!)
//
// with theta the angle from +z and phi the azimuth from +x toward +y. The seed's eq. 6 writes K_l^m
// in the m < 0 branch, which for negative m is not the normalisation (the factorials swap): lucent
// uses K_l^|m|. Sign convention (fixed once): P_l^m without the Condon-Shortley phase (-1)^m, as in
// Sloan's and Green's graphics notes, so that Y_1^1 = +sqrt(3 / 4 pi) x. Index i = l (l + 1) + m.
//
// Projection (eq. 7): c_i = integral f Y_i d omega; over N directions uniform on the sphere that
// is (4 pi / N) sum f(r_j) Y_i(r_j): the seed's eq. 7 omits the 4 pi. sh_quadrature() gives an
// exact rule for band-limited products (Gauss-Legendre in cos theta x uniform in phi).
#pragma once

#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace lucent::render {

inline constexpr int kShBands = 5;
inline constexpr int kShCoefficients = kShBands * kShBands;  // 25

template <typename T>
using ShVector = std::array<T, kShCoefficients>;

constexpr int sh_index(int l, int m) { return l * (l + 1) + m; }

/// The 25 real SH at the unit direction (x, y, z).
template <typename T>
ShVector<T> sh_basis(T x, T y, T z) {
  using std::atan2;
  using std::cos;
  using std::sin;
  using std::sqrt;
  ShVector<T> out{};
  const T ct = z;
  const T st = sqrt(std::max(T(0), T(1) - z * z));
  const T phi = atan2(y, x);
  // Associated Legendre P_l^m(ct) without the Condon-Shortley phase: P_m^m = (2m - 1)!! st^m,
  // P_{m+1}^m = ct (2m + 1) P_m^m, then (l - m) P_l^m = ct (2l - 1) P_{l-1}^m - (l + m - 1) P_{l-2}^m.
  T P[kShBands][kShBands] = {};
  T pmm = T(1);
  for (int m = 0; m < kShBands; ++m) {
    if (m > 0) pmm *= T(2 * m - 1) * st;
    P[m][m] = pmm;
    if (m + 1 < kShBands) P[m + 1][m] = ct * T(2 * m + 1) * pmm;
    for (int l = m + 2; l < kShBands; ++l) {
      P[l][m] = (ct * T(2 * l - 1) * P[l - 1][m] - T(l + m - 1) * P[l - 2][m]) / T(l - m);
    }
  }
  for (int l = 0; l < kShBands; ++l) {
    for (int m = 0; m <= l; ++m) {
      double ratio = 1;  // (l - m)! / (l + m)!
      for (int k = l - m + 1; k <= l + m; ++k) ratio /= k;
      const T K = T(std::sqrt((2 * l + 1) / (4 * std::numbers::pi) * ratio));
      if (m == 0) {
        out[std::size_t(sh_index(l, 0))] = K * P[l][0];
      } else {
        const T s2 = T(std::numbers::sqrt2);
        out[std::size_t(sh_index(l, m))] = s2 * K * cos(T(m) * phi) * P[l][m];
        out[std::size_t(sh_index(l, -m))] = s2 * K * sin(T(m) * phi) * P[l][m];
      }
    }
  }
  return out;
}

template <typename T>
ShVector<T> sh_basis(const Eigen::Matrix<T, 3, 1>& w) {
  return sh_basis<T>(w.x(), w.y(), w.z());
}

/// A quadrature rule on the sphere: directions and weights (summing to 4 pi).
struct ShQuadrature {
  std::vector<Eigen::Vector3d> directions;
  std::vector<double> weights;
};

/// Gauss-Legendre in cos theta (n nodes) x 2n uniform azimuths: exact for spherical polynomials of
/// degree < 2n (n = 5: every product of two band-4 functions).
ShQuadrature sh_quadrature(int n = 5);

/// c_i = integral f Y_i d omega by `rule`.
ShVector<double> sh_project(const std::function<double(const Eigen::Vector3d&)>& f,
                            const ShQuadrature& rule);

/// sum_i c_i Y_i(w).
double sh_evaluate(const ShVector<double>& c, const Eigen::Vector3d& w);

/// The coefficients of f(R^-1 w) from those of f (a band-limited function turned by R): per band,
/// exact, by evaluating the band at 2l + 1 fixed directions and inverting (the sampling method).
ShVector<double> sh_rotate(const ShVector<double>& c, const Eigen::Matrix3d& R);

/// The coefficients of a lobe max(0, w . d)^k (k = 1: the clamped cosine) about the unit d,
/// by quadrature (zonal: sqrt(4 pi / (2l + 1)) z_l Y_l^0(d) with its known z_l).
ShVector<double> sh_lobe(const Eigen::Vector3d& d, int exponent = 1, int nodes = 48);

}  // namespace lucent::render
