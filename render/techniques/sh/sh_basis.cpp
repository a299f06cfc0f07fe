// Real spherical harmonics, bands 0-4: quadrature, projection, rotation (sh_basis.h).
#include "lucent/render/sh_basis.h"

#include <Eigen/LU>

#include "lucent/materials/quadrature.h"

namespace lucent::render {

using materials::gauss_legendre;

ShQuadrature sh_quadrature(int n) {
  ShQuadrature rule;
  std::vector<double> mu, w;
  gauss_legendre(n, -1, 1, mu, w);
  const int azimuths = 2 * n;
  for (int i = 0; i < n; ++i) {
    const double s = std::sqrt(std::max(0.0, 1 - mu[std::size_t(i)] * mu[std::size_t(i)]));
    for (int j = 0; j < azimuths; ++j) {
      const double phi = 2 * std::numbers::pi * (j + 0.5) / azimuths;
      rule.directions.emplace_back(s * std::cos(phi), s * std::sin(phi), mu[std::size_t(i)]);
      rule.weights.push_back(w[std::size_t(i)] * 2 * std::numbers::pi / azimuths);
    }
  }
  return rule;
}

ShVector<double> sh_project(const std::function<double(const Eigen::Vector3d&)>& f,
                            const ShQuadrature& rule) {
  ShVector<double> c{};
  for (std::size_t k = 0; k < rule.directions.size(); ++k) {
    const double v = f(rule.directions[k]) * rule.weights[k];
    const ShVector<double> y = sh_basis<double>(rule.directions[k]);
    for (int i = 0; i < kShCoefficients; ++i) c[std::size_t(i)] += v * y[std::size_t(i)];
  }
  return c;
}

double sh_evaluate(const ShVector<double>& c, const Eigen::Vector3d& w) {
  const ShVector<double> y = sh_basis<double>(w);
  double sum = 0;
  for (int i = 0; i < kShCoefficients; ++i) sum += c[std::size_t(i)] * y[std::size_t(i)];
  return sum;
}

ShVector<double> sh_rotate(const ShVector<double>& c, const Eigen::Matrix3d& R) {
  // Per band, 2l + 1 directions on a spiral (fixed, well conditioned for these bands: the LU's
  // pivots are checked in tests/render/fur_test.cpp through exactness).
  ShVector<double> out{};
  const Eigen::Matrix3d inverse = R.transpose();
  for (int l = 0; l < kShBands; ++l) {
    const int n = 2 * l + 1;
    Eigen::MatrixXd A(n, n);
    Eigen::VectorXd values(n);
    for (int k = 0; k < n; ++k) {
      const double z = 1 - (2.0 * k + 1) / n * 0.999;
      const double phi = 2.399963229728653 * k + 0.3;  // golden angle
      const double s = std::sqrt(std::max(0.0, 1 - z * z));
      const Eigen::Vector3d d(s * std::cos(phi), s * std::sin(phi), z);
      const ShVector<double> y = sh_basis<double>(d), y_back = sh_basis<double>(Eigen::Vector3d(inverse * d));
      double v = 0;
      for (int m = -l; m <= l; ++m) {
        A(k, m + l) = y[std::size_t(sh_index(l, m))];
        v += c[std::size_t(sh_index(l, m))] * y_back[std::size_t(sh_index(l, m))];
      }
      values(k) = v;
    }
    const Eigen::VectorXd solved = A.fullPivLu().solve(values);
    for (int m = -l; m <= l; ++m) out[std::size_t(sh_index(l, m))] = solved(m + l);
  }
  return out;
}

ShVector<double> sh_lobe(const Eigen::Vector3d& d, int exponent, int nodes) {
  // Over the hemisphere about d only (the lobe is 0 elsewhere): Gauss-Legendre in mu = w . d on
  // [0, 1] and uniform azimuths, exact for the polynomial integrand mu^k Y_i.
  const Eigen::Vector3d axis = d.normalized();
  const Eigen::Vector3d e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
  std::vector<double> mu, w;
  gauss_legendre(nodes, 0, 1, mu, w);
  const int azimuths = 2 * nodes;
  ShVector<double> c{};
  for (int i = 0; i < nodes; ++i) {
    const double m = mu[std::size_t(i)], s = std::sqrt(std::max(0.0, 1 - m * m));
    const double lobe = std::pow(m, exponent) * w[std::size_t(i)] * 2 * std::numbers::pi / azimuths;
    for (int j = 0; j < azimuths; ++j) {
      const double phi = 2 * std::numbers::pi * (j + 0.5) / azimuths;
      const Eigen::Vector3d dir = m * axis + s * (std::cos(phi) * e1 + std::sin(phi) * e2);
      const ShVector<double> y = sh_basis<double>(dir);
      for (int k = 0; k < kShCoefficients; ++k) c[std::size_t(k)] += lobe * y[std::size_t(k)];
    }
  }
  return c;
}

}  // namespace lucent::render
