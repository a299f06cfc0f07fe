// Private pieces of the HDR merge (hdr_merge.cpp) shared with its noise model (hdr_noise.cpp): the
// stack of brackets as read, and the noise fits: from pairs of brackets (weighted non-negative
// least squares of var = a L + b) and, for a single image, from each pixel's spread around its
// neighbours.
#pragma once

#include <array>
#include <filesystem>
#include <vector>

#include "lucent/acquire/hdr_merge.h"
#include "lucent/imaging/image_io.h"

namespace lucent::acquire::detail {

struct Stack {
  std::vector<imaging::RawImage> images;
  std::vector<double> exposure_s;  ///< effective: the time, times ISO / 100 where the ISO is known
  std::vector<std::filesystem::path> paths;
  bool iso_known = false;
};

/// Quantisation variance of each code in linear units: the curve's local step squared over 12.
std::array<std::vector<double>, 3> quantisation_variance(const ResponseCurve& curve);

/// One observation of y ~ p a + q b with weight w.
struct NoiseRow {
  double a, b, y, w;
};

/// Non-negative weighted least squares of y ~ p a + q b (closed form on each face of the
/// constraint set). Returns {p, q}.
std::array<double, 2> fit_non_negative(const std::vector<NoiseRow>& rows);

/// The same reweighted: Var(d^2) = 2 E[d^2]^2 for a Gaussian difference, so each row is weighted
/// by the inverse square of its predicted E[d^2] (= p a + q b + floor), from unit weights.
std::array<double, 2> fit_variance_model(std::vector<NoiseRow>& rows,
                                         const std::vector<double>& floor);

/// The fallback noise model var(L) = a L + b from each pixel's spread around the mean of its four
/// neighbours, per channel. Fills result.noise.
void fit_neighbour_noise(HdrResult& result);

}  // namespace lucent::acquire::detail
