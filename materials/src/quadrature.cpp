#include "lucent/materials/quadrature.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <queue>

namespace lucent::materials {
namespace {

// Gauss-Kronrod 7-15 nodes and weights (abscissae on [0, 1], symmetric).
constexpr std::array<double, 8> kKronrodNodes = {
    0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
    0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
    0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
    0.207784955007898467600689403773245, 0.000000000000000000000000000000000};
constexpr std::array<double, 8> kKronrodWeights = {
    0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
    0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
    0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
    0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
// Gauss weights for the 7-point rule on the odd-indexed Kronrod nodes (1, 3, 5, 7).
constexpr std::array<double, 4> kGaussWeights = {
    0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
    0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

struct Panel {
  double a, b, value, error;
  bool operator<(const Panel& other) const { return error < other.error; }
};

Panel gauss_kronrod(const std::function<double(double)>& f, double a, double b) {
  const double centre = 0.5 * (a + b);
  const double half = 0.5 * (b - a);
  const double f_centre = f(centre);
  double kronrod = kKronrodWeights[7] * f_centre;
  double gauss = kGaussWeights[3] * f_centre;
  for (int i = 0; i < 7; ++i) {
    const double dx = half * kKronrodNodes[i];
    const double sum = f(centre - dx) + f(centre + dx);
    kronrod += kKronrodWeights[i] * sum;
    if (i % 2 == 1) gauss += kGaussWeights[i / 2] * sum;
  }
  return {a, b, kronrod * half, std::abs((kronrod - gauss) * half)};
}

}  // namespace

double integrate(const std::function<double(double)>& f, double a, double b, double rel_tol,
                 double abs_tol, int max_intervals) {
  std::priority_queue<Panel> panels;
  Panel first = gauss_kronrod(f, a, b);
  double value = first.value;
  double error = first.error;
  panels.push(first);
  for (int n = 1; n < max_intervals; ++n) {
    if (error <= std::max(abs_tol, rel_tol * std::abs(value))) break;
    const Panel worst = panels.top();
    panels.pop();
    const double mid = 0.5 * (worst.a + worst.b);
    const Panel left = gauss_kronrod(f, worst.a, mid);
    const Panel right = gauss_kronrod(f, mid, worst.b);
    value += left.value + right.value - worst.value;
    error += left.error + right.error - worst.error;
    panels.push(left);
    panels.push(right);
  }
  return value;
}

double integrate_over_plane(const std::function<double(double)>& f, double length_scale_mm,
                            double rel_tol) {
  const auto integrand = [&](double r) { return 2.0 * std::numbers::pi * r * f(r); };
  // Panels [0, s], [s, 2s], [2s, 4s], ...: fine where the profile is steep, growing where it
  // decays.
  double total = integrate(integrand, 0.0, length_scale_mm, rel_tol * 0.1);
  double a = length_scale_mm;
  int small_panels = 0;
  for (int i = 0; i < 200 && small_panels < 4; ++i) {
    const double b = 2.0 * a;
    const double part = integrate(integrand, a, b, rel_tol * 0.1);
    total += part;
    small_panels = std::abs(part) < rel_tol * 1e-2 * std::abs(total) ? small_panels + 1 : 0;
    a = b;
  }
  return total;
}

void gauss_legendre(int n, double a, double b, std::vector<double>& x, std::vector<double>& w) {
  x.assign(std::size_t(n), 0.0);
  w.assign(std::size_t(n), 0.0);
  for (int i = 0; i < n; ++i) {
    double t = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
    double dp = 1;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p0 = 1, p1 = t;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * t * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      const double p = n == 0 ? 1 : p1, pm = p0;
      dp = n * (t * p - pm) / (t * t - 1);
      const double step = p / dp;
      t -= step;
      if (std::abs(step) < 1e-16) break;
    }
    x[std::size_t(i)] = 0.5 * (b - a) * t + 0.5 * (b + a);
    w[std::size_t(i)] = (b - a) / ((1 - t * t) * dp * dp);
  }
}

}  // namespace lucent::materials
