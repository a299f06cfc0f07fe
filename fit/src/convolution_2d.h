// The system response convolved into 2D samples (oblique captures): the model's pixel means on a
// square grid of cells, convolved with the response by FFT (zero-padded: a linear convolution),
// then read at each sample by bilinear interpolation. Internal to lucent_fit.
//
// Radial bins take a precomputed linear map from the model at a few hundred radii
// (system_response.h); a 2D profile has no such symmetry, so the model is needed at every cell the
// response can carry light from. Convolution is linear, so with automatic derivatives the value
// and each derivative are convolved alike (one FFT pair each).
#pragma once

#include <ceres/jet.h>

#include <array>
#include <complex>
#include <functional>
#include <memory>
#include <vector>

namespace lucent::fit::detail {

struct Convolution2d {
  int nx = 0, ny = 0;   ///< cells along x and y (the model is evaluated at their centres)
  int mx = 0, my = 0;   ///< the padded FFT size (powers of 2, >= 2 n)
  double h = 0;         ///< cell side, mm
  double x0 = 0, y0 = 0;  ///< the centre of cell (0, 0), mm
  std::vector<std::complex<double>> kernel;  ///< FFT of the response on the padded grid
  /// Per sample: the 4 cells (indices y * nx + x) and bilinear weights it is read from.
  std::vector<std::array<int, 4>> cells;
  std::vector<std::array<double, 4>> weights;
  double cell_x(int i) const { return x0 + i * h; }
  double cell_y(int j) const { return y0 + j * h; }
};

/// The set-up for samples at (x, y) (mm; pixel: their footprint side, mm) and a radially symmetric
/// response `density` (per mm^2 of radius r mm, unit integral) that is 0 beyond `extent_mm`. Cells
/// are the pixels, or groups of them so that at most max_cells lie along a side; the grid spans the
/// samples and the entry point.
std::shared_ptr<const Convolution2d> make_convolution_2d(
    const std::vector<double>& x, const std::vector<double>& y, double pixel,
    const std::function<double(double)>& density, double extent_mm, int max_cells = 128);

/// grid (nx * ny values, row y) replaced by its convolution with the response.
void convolve(const Convolution2d& c, std::vector<double>& grid);

template <int N>
void convolve(const Convolution2d& c, std::vector<ceres::Jet<double, N>>& grid) {
  std::vector<double> part(grid.size());
  for (int k = -1; k < N; ++k) {
    for (std::size_t i = 0; i < grid.size(); ++i) part[i] = k < 0 ? grid[i].a : grid[i].v[k];
    convolve(c, part);
    for (std::size_t i = 0; i < grid.size(); ++i) (k < 0 ? grid[i].a : grid[i].v[k]) = part[i];
  }
}

}  // namespace lucent::fit::detail
