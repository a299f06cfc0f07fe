// 2D convolution with the system response (convolution_2d.h).
#include "convolution_2d.h"

#include <unsupported/Eigen/FFT>

#include <algorithm>
#include <cmath>

namespace lucent::fit::detail {
namespace {

int padded(int n) {
  int m = 1;
  while (m < 2 * n) m *= 2;
  return m;
}

// In-place 2D FFT of an mx by my array (row y), rows then columns.
void fft2(std::vector<std::complex<double>>& a, int mx, int my, bool inverse) {
  static thread_local Eigen::FFT<double> fft;
  std::vector<std::complex<double>> in, out;
  in.resize(std::size_t(std::max(mx, my)));
  for (int y = 0; y < my; ++y) {
    in.assign(a.begin() + long(y) * mx, a.begin() + long(y + 1) * mx);
    if (inverse) fft.inv(out, in); else fft.fwd(out, in);
    std::copy(out.begin(), out.end(), a.begin() + long(y) * mx);
  }
  in.resize(std::size_t(my));
  for (int x = 0; x < mx; ++x) {
    for (int y = 0; y < my; ++y) in[std::size_t(y)] = a[std::size_t(y) * mx + x];
    if (inverse) fft.inv(out, in); else fft.fwd(out, in);
    for (int y = 0; y < my; ++y) a[std::size_t(y) * mx + x] = out[std::size_t(y)];
  }
}

}  // namespace

std::shared_ptr<const Convolution2d> make_convolution_2d(
    const std::vector<double>& x, const std::vector<double>& y, double pixel,
    const std::function<double(double)>& density, double extent_mm, int max_cells) {
  auto c = std::make_shared<Convolution2d>();
  double xmin = 0, xmax = 0, ymin = 0, ymax = 0;  // the entry point included
  for (std::size_t i = 0; i < x.size(); ++i) {
    xmin = std::min(xmin, x[i]), xmax = std::max(xmax, x[i]);
    ymin = std::min(ymin, y[i]), ymax = std::max(ymax, y[i]);
  }
  const double p = pixel > 0 ? pixel : 0.1;
  const double span = std::max(xmax - xmin, ymax - ymin);
  const int group = std::max(1, int(std::ceil((span / p + 1) / max_cells)));
  c->h = p * group;
  c->x0 = xmin, c->y0 = ymin;
  c->nx = int(std::floor((xmax - xmin) / c->h + 1e-9)) + 2;
  c->ny = int(std::floor((ymax - ymin) / c->h + 1e-9)) + 2;
  c->mx = padded(c->nx), c->my = padded(c->ny);
  // The response at every offset the padded grid holds, wrapped, normalised to unit sum. The cells
  // hold the model's pixel means already, so the response is taken at the cell centres (the
  // midpoint rule, spectrally accurate for a smooth response sampled finer than its width: a
  // Gaussian of 2 cells sigma to 1e-8); cells of grouped pixels, coarser than a core of a few
  // pixels, take its mean over 4 x 4 points instead.
  const int sub = group == 1 ? 1 : 4;
  std::vector<std::complex<double>> k(std::size_t(c->mx) * c->my, 0.0);
  double sum = 0;
  const int reach_x = std::min(c->mx / 2, int(std::ceil(extent_mm / c->h)) + 1);
  const int reach_y = std::min(c->my / 2, int(std::ceil(extent_mm / c->h)) + 1);
  for (int j = -reach_y; j < reach_y; ++j)
    for (int i = -reach_x; i < reach_x; ++i) {
      double mean = 0;
      for (int a = 0; a < sub; ++a)
        for (int b = 0; b < sub; ++b)
          mean += density(std::hypot((i + (a + 0.5) / sub - 0.5) * c->h,
                                     (j + (b + 0.5) / sub - 0.5) * c->h));
      const double w = mean / (sub * sub) * c->h * c->h;
      k[std::size_t((j + c->my) % c->my) * c->mx + std::size_t((i + c->mx) % c->mx)] = w;
      sum += w;
    }
  if (sum > 0)
    for (auto& v : k) v /= sum;
  fft2(k, c->mx, c->my, false);
  c->kernel = std::move(k);
  for (std::size_t s = 0; s < x.size(); ++s) {
    const double fx = (x[s] - c->x0) / c->h, fy = (y[s] - c->y0) / c->h;
    const int ix = std::clamp(int(std::floor(fx)), 0, c->nx - 2);
    const int iy = std::clamp(int(std::floor(fy)), 0, c->ny - 2);
    const double tx = std::clamp(fx - ix, 0.0, 1.0), ty = std::clamp(fy - iy, 0.0, 1.0);
    c->cells.push_back({iy * c->nx + ix, iy * c->nx + ix + 1, (iy + 1) * c->nx + ix,
                        (iy + 1) * c->nx + ix + 1});
    c->weights.push_back({(1 - tx) * (1 - ty), tx * (1 - ty), (1 - tx) * ty, tx * ty});
  }
  return c;
}

void convolve(const Convolution2d& c, std::vector<double>& grid) {
  std::vector<std::complex<double>> a(std::size_t(c.mx) * c.my, 0.0);
  for (int y = 0; y < c.ny; ++y)
    for (int x = 0; x < c.nx; ++x)
      a[std::size_t(y) * c.mx + x] = grid[std::size_t(y) * c.nx + x];
  fft2(a, c.mx, c.my, false);
  for (std::size_t i = 0; i < a.size(); ++i) a[i] *= c.kernel[i];
  fft2(a, c.mx, c.my, true);
  for (int y = 0; y < c.ny; ++y)
    for (int x = 0; x < c.nx; ++x)
      grid[std::size_t(y) * c.nx + x] = a[std::size_t(y) * c.mx + x].real();
}

}  // namespace lucent::fit::detail
