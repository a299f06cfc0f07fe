// The system response of a real bench (system_response.h).
#include "system_response.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

namespace lucent::fit::detail {

double bessel_i0e(double x) {
  x = std::abs(x);
  if (x < 3.75) {
    const double t = (x / 3.75) * (x / 3.75);
    return std::exp(-x) *
           (1 + t * (3.5156229 + t * (3.0899424 + t * (1.2067492 +
                                                       t * (0.2659732 + t * (0.0360768 + t * 0.0045813))))));
  }
  const double t = 3.75 / x;
  return (0.39894228 +
          t * (0.01328592 +
               t * (0.00225319 +
                    t * (-0.00157565 +
                         t * (0.00916281 +
                              t * (-0.02057706 + t * (0.02635537 + t * (-0.01647633 + t * 0.00392377)))))))) /
         std::sqrt(x);
}

namespace {

// The rms radius of the response's core (the rings above 1e-4 of its peak), mm, and the share of
// its light beyond 3 pixels; {0, 0} without a response.
std::pair<double, double> core_and_glare(const ProfileData& d) {
  const std::vector<double>& r = d.response_r_mm;
  const std::vector<double>& v = d.response_value;
  if (r.size() < 2 || r.size() != v.size()) return {0.0, 0.0};
  const double pixel = d.radial.pixel_mm;
  // The rings as annuli about their radii (rings of equal width), down to where the response
  // falls below 1e-4 of its peak: the noise of the white reference's dark field must not pass for
  // width (its r^2-weighted sum is large and of either sign).
  const double peak = *std::max_element(v.begin(), v.end());
  double energy = 0, second = 0, outside = 0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    const double width = i + 1 < r.size() ? r[i + 1] - r[i] : r[i] - r[i - 1];
    const double ring = 2 * std::numbers::pi * r[i] * width * std::max(0.0, v[i]);
    if (v[i] >= 1e-4 * peak) energy += ring, second += ring * r[i] * r[i];
    if (pixel > 0 && r[i] > 3 * pixel) outside += ring;  // glare, whatever its level
  }
  if (!(energy > 0)) return {0.0, 0.0};
  return {std::sqrt(second / energy), outside};
}

// The measured response as a function of radius, mm: linear between its rings, its first value
// inside them; past the last ring above the noise, a power-law glare tail where the outer rings fall
// like one, out to `reach` (else 0). A lens's veil falls as r^-3 far out; the white reference's rings
// sink into its dark field's noise (they are 0 within 3 SE) well before the sample's own tail ends,
// and that tail, six decades below its peak, still carries the veil of its bright centre: without
// the tail a skin1 capture with 3% glare left 11 SD of structure in green (4.2 with it).
struct MeasuredKernel {
  const std::vector<double>* kr = nullptr;
  const std::vector<double>* kv = nullptr;
  // The tail v_last ((r_last^2 + a2) / (x^2 + a2))^(power / 2); power 0: none.
  double r_last = 0, v_last = 0, power = 0, a2 = 0;
  double reach = 0;                          // 0 beyond
  double operator()(double x) const {
    const std::vector<double>& r = *kr;
    const std::vector<double>& v = *kv;
    if (x <= r.front()) return std::max(0.0, v.front());
    if (x >= reach) return 0.0;
    if (power > 0 && x > r_last)
      return x < reach ? v_last * std::pow((r_last * r_last + a2) / (x * x + a2), power / 2) : 0.0;
    if (x >= r.back()) return 0.0;
    const auto hi = std::size_t(std::upper_bound(r.begin(), r.end(), x) - r.begin());
    const double t = (x - r[hi - 1]) / (r[hi] - r[hi - 1]);
    return std::max(0.0, v[hi - 1] + t * (v[hi] - v[hi - 1]));
  }
};

MeasuredKernel measured_kernel(const ProfileData& d, double reach_mm) {
  MeasuredKernel k;
  k.kr = &d.response_r_mm, k.kv = &d.response_value;
  const std::vector<double>& r = d.response_r_mm;
  const std::vector<double>& v = d.response_value;
  // The last of two rings in a row above the noise: a lone ring far out is a fluctuation of the
  // dark field (1 in 700 rings passes 3 SE), and at 27 mm it put 4e-7 of the beam where a potato's
  // far tail is that faint (structure 10 SD). Nothing of the response is used past it.
  std::size_t last = 0;
  for (std::size_t i = 1; i < r.size(); ++i)
    if (v[i] > 0 && v[i - 1] > 0) last = i;
  k.reach = r[std::min(last + 1, r.size() - 1)];
  if (last < 4) return k;
  // The outer rings' log-log slope, over the last factor of 2 in radius.
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i <= last; ++i) {
    if (!(v[i] > 0) || r[i] < 0.5 * r[last] || !(r[i] > 0)) continue;
    const double x = std::log(r[i]), y = std::log(v[i]);
    n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  if (n < 4 || !(sxx * n - sx * sx > 0)) return k;
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  // A power law (glare), not a Gaussian core's edge (slope -r^2/sigma^2: -16 at 4 sigma). A slope
  // shallower than -3 is a veil a / (r^2 + a^2)^1.5 still bending toward its r^-3 asymptote: its a
  // from the slope at the rings' mean radius (slope = -3 r^2 / (r^2 + a^2)); steeper, r^slope.
  if (!(slope > -6 && slope < -1)) return k;
  const double r_mid = std::exp(sx / n);
  k.power = std::max(3.0, -slope);
  k.a2 = slope > -3 ? r_mid * r_mid * (-3 / slope - 1) : 0.0;
  k.r_last = r[last];
  k.v_last = std::exp(sy / n + slope * (std::log(k.r_last) - sx / n));  // the fitted line there
  k.reach = std::max(r.back(), reach_mm);
  return k;
}


// What a fit convolves with, for the report.
std::string response_text(const ProfileData& d, double beam_sigma_mm) {
  std::ostringstream what;
  what.precision(3);
  if (beam_sigma_mm > 0)
    what << "a Gaussian beam of sigma " << beam_sigma_mm << " mm (--beam-sigma-mm)";
  else
    what << "the system response " << d.response_source << " (rms radius " << d.response_rms_mm
         << " mm over the whole field)";
  return what.str();
}

}  // namespace

bool response_is_wide(const ProfileData& d) {
  const auto [rms, outside] = core_and_glare(d);
  if (!(rms > 0)) return false;
  const double pixel = d.radial.pixel_mm;
  // Wider than the pixels' own footprint (a pencil beam through a sharp lens gives a spot of about
  // one pixel sigma: rms 1.4-1.5 pixels, 1.1% of it beyond 3 pixels), or a glare veil of 2% or more.
  return pixel > 0 ? rms > 2 * pixel || outside > 0.02 : rms > 0;
}

// 2D samples: the grid convolution (convolution_2d.h) with a Gaussian of beam_sigma_mm (the
// cells' own footprint is in the model), or the measured response where it is wide.
// 2D samples: the grid convolution (convolution_2d.h) with a Gaussian of beam_sigma_mm (the
// cells' own footprint is in the model), or the measured response where it is wide.
static std::string attach_2d(Observations& o, const ProfileData& d, double beam_sigma_mm) {
  const bool gaussian = beam_sigma_mm > 0;
  if (!gaussian && !response_is_wide(d)) return "";
  double reach = 0;  // the samples' farthest distance from the entry
  for (std::size_t i = 0; i < o.x.size(); ++i) reach = std::max(reach, std::hypot(o.x[i], o.y[i]));
  const MeasuredKernel measured = gaussian ? MeasuredKernel{} : measured_kernel(d, 2 * reach);
  const auto density = [&](double x) {
    return gaussian ? std::exp(-x * x / (2 * beam_sigma_mm * beam_sigma_mm)) /
                          (2 * std::numbers::pi * beam_sigma_mm * beam_sigma_mm)
                    : measured(x);
  };
  o.conv2d = make_convolution_2d(o.x, o.y, o.pixel, density,
                                 gaussian ? 6 * beam_sigma_mm : measured.reach);
  return response_text(d, beam_sigma_mm) + " (2D samples: on a grid of cells, by FFT)";
}

std::string attach_system_response(Observations& o, const ProfileData& d, double beam_sigma_mm) {
  o.conv_nodes.clear();
  o.conv_weights.clear();
  o.conv_point.clear();
  o.conv2d.reset();
  if (o.r.empty() && !o.x.empty() && o.linear) return attach_2d(o, d, beam_sigma_mm);
  if (o.linear || o.r.empty()) return "";
  const double pixel = d.radial.pixel_mm;
  const bool gaussian = beam_sigma_mm > 0;
  const bool measured = !gaussian && response_is_wide(d);
  if (!gaussian && !measured) return "";
  const double sigma =
      gaussian ? std::sqrt(beam_sigma_mm * beam_sigma_mm + (pixel > 0 ? pixel * pixel / 12 : 0.0))
               : 0.0;
  const std::vector<double>& kr = d.response_r_mm;
  const std::vector<double>& kv = d.response_value;
  const MeasuredKernel kernel =
      measured ? measured_kernel(d, 2 * o.r.back()) : MeasuredKernel{};
  // Node spacing: an eighth of the Gaussian's sigma, or a sixth of the measured core's half width
  // at half maximum (the glare's long tail does not set it), never below a quarter pixel. (A
  // quarter sigma left the midpoint rule 0.7% high at the centre of a Gaussian.)
  double core = sigma;
  if (measured) {
    const double half = 0.5 * *std::max_element(kv.begin(), kv.end());
    core = kr.back();
    for (std::size_t i = 0; i < kr.size(); ++i)
      if (kv[i] < half) {
        core = std::max(kr[i], 1e-3);
        break;
      }
  }
  const double h = std::max({gaussian ? sigma / 8 : core / 6, pixel / 4, 1e-3});
  const double extent = gaussian ? 6 * sigma : kernel.reach;
  const double s_max = o.r.back() + extent;
  const std::size_t m = std::size_t(std::ceil(s_max / h));
  for (std::size_t j = 0; j < m; ++j) o.conv_nodes.push_back((double(j) + 0.5) * h);
  o.conv_weights.assign(o.r.size() * m, 0.0);
  o.conv_point.clear();
  for (const double r : o.r)
    o.conv_point.push_back(gaussian ? std::exp(-r * r / (2 * sigma * sigma)) /
                                          (2 * std::numbers::pi * sigma * sigma)
                                    : kernel(r));
  constexpr int kAngles = 96;  // midpoints over [0, pi] for the measured response
  for (std::size_t i = 0; i < o.r.size(); ++i) {
    const double r = o.r[i];
    for (std::size_t j = 0; j < m; ++j) {
      const double s = o.conv_nodes[j];
      double a = 0;
      if (gaussian) {
        if (std::abs(r - s) > 8 * sigma) continue;
        const double d2 = (r - s) * (r - s);
        a = std::exp(-d2 / (2 * sigma * sigma)) * bessel_i0e(r * s / (sigma * sigma)) /
            (sigma * sigma);
      } else {
        if (std::abs(r - s) >= kernel.reach) continue;
        // Only the arc within the response's reach: far out (r = 50 mm) a 3 mm response spans
        // 0.06 rad of the circle, which midpoints over the whole of [0, pi] sampled 2 to 4 times
        // (a potato's far tail then left 10 SD of structure).
        const double c = (r * r + s * s - kernel.reach * kernel.reach) / (2 * r * s);
        const double arc = c <= -1 ? std::numbers::pi : c >= 1 ? 0.0 : std::acos(c);
        for (int k = 0; k < kAngles; ++k) {
          const double theta = (k + 0.5) * arc / kAngles;
          a += kernel(std::sqrt(std::max(0.0, r * r + s * s - 2 * r * s * std::cos(theta))));
        }
        a *= 2 * arc / kAngles;
      }
      o.conv_weights[i * m + j] = h * s * a;
    }
  }
  return response_text(d, beam_sigma_mm);
}

std::string describe_system_response(const ProfileData& d, double beam_sigma_mm) {
  Observations probe;
  if (d.samples_2d.has_value() && d.incidence_polar_deg > 0) {  // 2D samples
    probe.x = {1.0}, probe.y = {0.0}, probe.linear = true, probe.pixel = d.samples_2d->pixel_mm;
  } else {
    probe.r = {1.0};
  }
  const std::string what = attach_system_response(probe, d, beam_sigma_mm);
  return d.source + ": " +
         (what.empty() ? "a pencil beam and a sharp lens assumed (no system response wider than "
                         "the pixels)"
                       : "the model is convolved with " + what);
}

}  // namespace lucent::fit::detail
