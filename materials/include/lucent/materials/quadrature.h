// Numerical quadrature for the model checks that have no closed form (totals of the directional
// dipole, moments of the Fresnel reflectance) and for the tests that hold closed forms to account.
#pragma once

#include <array>
#include <cmath>
#include <functional>
#include <vector>

namespace lucent::materials {

/// Adaptive 15-point Gauss-Kronrod quadrature of f over [a, b] to the requested absolute or
/// relative tolerance (whichever is reached first), at most `max_intervals` subdivisions.
double integrate(const std::function<double(double)>& f, double a, double b, double rel_tol = 1e-10,
                 double abs_tol = 0.0, int max_intervals = 2000);

/// Gauss-Legendre nodes x and weights w of order n on [a, b] (Newton on P_n from the Chebyshev
/// guesses): exact for polynomials of degree 2n - 1.
void gauss_legendre(int n, double a, double b, std::vector<double>& x, std::vector<double>& w);

/// Integral of a radially symmetric function over the whole plane: 2 pi int_0^inf r f(r) dr.
/// `length_scale_mm` sets where the panels start (use a mean free path): the range is cut into
/// geometrically growing panels, each integrated adaptively, until a panel adds less than rel_tol
/// of the running total for several panels in a row.
double integrate_over_plane(const std::function<double(double)>& f, double length_scale_mm,
                            double rel_tol = 1e-10);

}  // namespace lucent::materials
