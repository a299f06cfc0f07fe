// Chandrasekhar's H-function and the angular factor of multiple scattering (angular.h).
#include "lucent/materials/angular.h"

#include <algorithm>
#include <numbers>

#include "lucent/materials/quadrature.h"

namespace lucent::materials {
namespace {

// cos of the refracted direction inside for an outside cosine (eta = n_inside / n_outside >= 1).
double inside_cosine(double cos_outside, double eta) {
  const double c = std::clamp(cos_outside, 0.0, 1.0);
  return std::sqrt(std::max(0.0, 1 - (1 - c * c) / (eta * eta)));
}

}  // namespace

HFunction::HFunction(double omega) : omega_(std::clamp(omega, 0.0, 1.0)) {
  gauss_legendre(48, 0, 1, mu_, weight_);
  h_.assign(mu_.size(), 1.0);
  const double root = std::sqrt(1 - omega_);
  std::vector<double> next(h_.size());
  for (int it = 0; it < 2000; ++it) {  // ~40 suffice
    double change = 0;
    for (std::size_t i = 0; i < mu_.size(); ++i) {
      double sum = 0;
      for (std::size_t j = 0; j < mu_.size(); ++j)
        sum += weight_[j] * mu_[j] * h_[j] / (mu_[i] + mu_[j]);
      // Damped by half: undamped, the iteration oscillates without converging at omega = 1.
      next[i] = 0.5 * h_[i] + 0.5 / (root + 0.5 * omega_ * sum);
      change = std::max(change, std::abs(next[i] - h_[i]));
    }
    h_.swap(next);
    if (change < 1e-13) break;
  }
}

double HFunction::operator()(double mu) const {
  double sum = 0;
  for (std::size_t j = 0; j < mu_.size(); ++j) sum += weight_[j] * mu_[j] * h_[j] / (mu + mu_[j]);
  return 1 / (std::sqrt(1 - omega_) + 0.5 * omega_ * sum);
}

AngularFactor::AngularFactor(const Material& material) : eta_(std::max(material.ior, 1.0)) {
  for (int c = 0; c < 3; ++c) {
    const double s = material.sigma_s_reduced[c], a = material.sigma_a[c];
    albedo_[std::size_t(c)] = s + a > 0 ? s / (s + a) : 0.0;
    const HFunction H(albedo_[std::size_t(c)]);
    const double h1 = H(1.0);
    const double normal = h1 * h1 - 1;
    for (int i = 0; i < kNodes; ++i) {
      const double mu = std::max(inside_cosine(double(i) / (kNodes - 1), eta_), 1e-4);
      const double h = H(mu);
      // k = sqrt(K(mu, mu)) = sqrt((H^2 - 1) / (2 mu) / ((H(1)^2 - 1) / 2)); 1 where nothing
      // scatters more than once.
      nodes_[std::size_t(c)][std::size_t(i)] =
          normal > 1e-12 ? std::sqrt(std::max(h * h - 1, 0.0) / (mu * normal)) : 1.0;
    }
  }
}

double AngularFactor::two_sided(int c, double cos_i, double cos_o) const {
  const HFunction H(albedo_[std::size_t(c)]);
  const double mi = std::max(inside_cosine(cos_i, eta_), 1e-4);
  const double mo = std::max(inside_cosine(cos_o, eta_), 1e-4);
  const double h1 = H(1.0);
  const double normal = (h1 * h1 - 1) / 2;
  return normal > 1e-12 ? (H(mi) * H(mo) - 1) / (mi + mo) / normal : 1.0;
}

}  // namespace lucent::materials
