// The fit's model of a real bench: the pencil-beam response convolved with the system response
// the white reference recorded (beam footprint, lens blur, veiling glare, pixel), or with a
// Gaussian beam the user gives. Internal to lucent_fit.
//
// Convolution of the model, not deconvolution of the data: the data keep their own noise and
// standard errors (a deconvolution amplifies the noise at the frequencies the response damps, and
// its regularisation biases exactly the near field that carries sigma_s'), and the model is
// smooth, so the convolution is a fixed linear map, computed once per fit: each bin's value is a
// weighted sum of the model at M radii, sum_j W_ij f(s_j), W_ij = h s_j A(r_i, s_j), with A the
// response's integral around the circle of radius s about a point at distance r (for a Gaussian
// of sigma, A = e^(-(r - s)^2 / 2 sigma^2) I0e(r s / sigma^2) / sigma^2).
#pragma once

#include <string>

#include "fit_residuals.h"

namespace lucent::fit::detail {

/// e^-x I0(x), x >= 0 (Abramowitz and Stegun 9.8.1-2, relative error below 2e-7).
double bessel_i0e(double x);

/// Whether the data's measured response is more than its pixels make: its core's rms radius (the
/// rings above 1e-4 of the peak) above 2 pixels, or 2% of it beyond 3 pixels (glare).
bool response_is_wide(const ProfileData& d);

/// Fills o.conv_nodes and o.conv_weights for radial bins (o.r), or o.conv2d for 2D samples
/// (convolution_2d.h), when a response applies: a Gaussian of beam_sigma_mm (> 0; with the pixel's
/// own spread added for pixel bins), else the data's measured response when response_is_wide.
/// Returns what was applied, for the report ("" when nothing).
std::string attach_system_response(Observations& o, const ProfileData& d, double beam_sigma_mm);

/// What the fit did about an input's system response, for the report: convolved with what, or a
/// pencil beam and a sharp lens assumed.
std::string describe_system_response(const ProfileData& d, double beam_sigma_mm);

}  // namespace lucent::fit::detail
