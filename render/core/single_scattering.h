// The single-scattering term of Jensen et al. 2001 (seed 000 §2.4, eq. 4 with its refracted path
// length s_i'), evaluated by a fixed quadrature along the refracted view ray. This is the C++ twin
// of render/gl/shaders/single_scattering.glsl: the radiance maps' final pass evaluates that one
// with the light maps as `entry`, the hierarchical technique evaluates this one at its vertices
// with Embree rays. (The reference and pathtrace draw the same term by Monte Carlo with the exact
// refracted connection: render/pathtrace/path_walk.h.)
//
// Radiance leaving x_o toward w_o from one collision inside, per channel c:
//   L_c = F_t(cos_o) / eta^2  integral_0^inf  sigma_s p_g(d_in . -t) E_in e^(-sigma_t s_i')
//   e^(-sigma_t s) ds
// t the refracted view ray (into the medium), x = x_o + s t; the light's entry point x_i is where
// the straight line from x toward the light leaves the medium, at distance s_i, normal n_i;
//   s_i' = s_i cos_i / cos_ti         (Jensen's refracted path length: exact for a plane),
//   E_in = E F_t(cos_i) cos_i / cos_ti (the refracted beam's irradiance across itself),
// d_in the refracted travel direction at x_i. The quadrature substitutes u = 1 - e^(-sigma_t s) and
// takes the midpoints of `steps` equal strata of u: exact (to rounding) for a plane lit and seen
// along its normal, where the integrand is linear in u; within 0.5% for a plane lit and seen at
// 60 degrees with 8 steps (tests/render/single_scattering_test.cpp holds it to the closed form).
// Channels whose sigma_t are within 1.25 of each other (potato, marble) share one set of points,
// drawn for the smallest, each weighted by e^(-(sigma_t - sigma_ref) s): one light-map read per
// point instead of three (within 1% of the closed form at normal incidence, measured in the test);
// within 2 (skin1) they share 3/2 as many points (12: within 1% too).
// Stated approximations: a curved boundary is the plane at x_i (Jensen's); a point light's entry is
// on the straight line; points beyond the object's far side count as inside when `entry` finds a
// surface toward the light (negligible beyond a few mean free paths).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "lucent/materials/fresnel.h"
#include "lucent/materials/material.h"

namespace lucent::render::detail {

/// The medium per channel: sigma_s, sigma_t (mm^-1), the Henyey-Greenstein g; relative index eta.
struct SingleMedium {
  std::array<double, 3> sigma_s{}, sigma_t{}, g{};
  double eta = 1;
  static SingleMedium of(const materials::Material& material) {
    SingleMedium m;
    m.eta = material.ior;
    for (int c = 0; c < 3; ++c) {
      const materials::Medium<double> medium = material.medium(c);
      m.sigma_s[std::size_t(c)] = medium.sigma_s;
      m.sigma_t[std::size_t(c)] = medium.sigma_a + medium.sigma_s;
      m.g[std::size_t(c)] = medium.g;
    }
    return m;
  }
};

/// What lies toward the light from a point x inside: the distance (mm) along the straight line to
/// where it leaves the medium and the surface's outward shading normal there; found false when no
/// surface is there (x is outside).
struct LightEntry {
  bool found = false;
  double distance_mm = 0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

/// One light: directional (`toward` the unit direction toward it, `radiance` the irradiance on a
/// surface facing it) or point (`toward` its position in mm, `radiance` its intensity).
struct SingleLight {
  bool point = false;
  Eigen::Vector3d toward = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d radiance = Eigen::Vector3d::Ones();
};

constexpr int kSingleScatteringSteps = 8;
/// Channels whose sigma_t are within kShareRatio share the quadrature's `steps` points; within
/// kShareRatioWide (skin1: 1.93) they share 3/2 as many (12 for 8: 0.5-0.8% of the closed form at
/// a ratio of 1.6-1.9, where 8 shared points were 1.2-1.8%; 12 look-ups instead of 24).
constexpr double kShareRatio = 1.25;
constexpr double kShareRatioWide = 2.0;

/// The quadrature's points per set for channels whose sigma_t span lo..hi (per channel: `steps`).
inline int shared_steps(double lo, double hi, int steps) {
  return hi <= kShareRatio * lo ? steps : (3 * steps + 1) / 2;
}

/// The single-scattering radiance (per channel) leaving x_o (outward normal n_o) toward the unit
/// w_o lit by `light`; `entry(x, w)` -> LightEntry finds the light's entry point from x toward w.
template <typename Entry>
Eigen::Vector3d single_scattering_radiance(const SingleMedium& m, const Eigen::Vector3d& x_o,
                                           const Eigen::Vector3d& n_o, const Eigen::Vector3d& w_o,
                                           const SingleLight& light, int steps, Entry&& entry) {
  Eigen::Vector3d L = Eigen::Vector3d::Zero();
  const double cos_o = n_o.dot(w_o);
  if (!(cos_o > 0)) return L;
  const double eta = m.eta;
  const double cos_to = std::sqrt(std::max(0.0, 1 - (1 - cos_o * cos_o) / (eta * eta)));
  const Eigen::Vector3d t = -w_o / eta + (cos_o / eta - cos_to) * n_o;  // into the medium
  const double leaving = materials::fresnel_transmittance(cos_o, eta) / (eta * eta);
  // One set of points for all channels when their sigma_t are within kShareRatioWide (one entry
  // look-up per point instead of three), drawn for the smallest; else a set per channel.
  const double lo = std::min({m.sigma_t[0], m.sigma_t[1], m.sigma_t[2]});
  const double hi = std::max({m.sigma_t[0], m.sigma_t[1], m.sigma_t[2]});
  const bool shared = lo > 0 && hi <= kShareRatioWide * lo;
  const int n = shared ? shared_steps(lo, hi, steps) : steps;
  for (int group = 0; group < (shared ? 1 : 3); ++group) {
    const double sigma_ref = shared ? lo : m.sigma_t[std::size_t(group)];
    if (!(sigma_ref > 0)) continue;
    const int first = shared ? 0 : group, last = shared ? 2 : group;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int k = 0; k < n; ++k) {
      const double u = (k + 0.5) / n;
      const double s = -std::log1p(-u) / sigma_ref;
      const Eigen::Vector3d x = x_o + s * t;
      const Eigen::Vector3d w =
          light.point ? Eigen::Vector3d((light.toward - x).normalized()) : light.toward;
      const LightEntry e = entry(x, w);
      if (!e.found || !(e.distance_mm >= 0)) continue;
      const double cos_i = w.dot(e.normal);
      if (!(cos_i > 0)) continue;  // the surface there faces away from the light
      const double cos_ti = std::sqrt(std::max(0.0, 1 - (1 - cos_i * cos_i) / (eta * eta)));
      const double s_in = e.distance_mm * cos_i / cos_ti;
      double falloff = 1;
      if (light.point) {
        falloff = 1 / std::max((light.toward - (x + e.distance_mm * w)).squaredNorm(), 1e-12);
      }
      const double T_in = materials::fresnel_transmittance(cos_i, eta) * cos_i / cos_ti;
      const Eigen::Vector3d d_in = -w / eta + (cos_i / eta - cos_ti) * e.normal;
      for (int c = first; c <= last; ++c) {
        const double sigma_t = m.sigma_t[std::size_t(c)];
        const double phase = materials::henyey_greenstein(m.g[std::size_t(c)], -d_in.dot(t));
        // e^(-(sigma_t - sigma_ref) s): the points were drawn for sigma_ref.
        sum[c] += m.sigma_s[std::size_t(c)] * phase * light.radiance[c] * falloff * T_in *
                  std::exp(-sigma_t * s_in - (sigma_t - sigma_ref) * s);
      }
    }
    for (int c = first; c <= last; ++c) L[c] = leaving * sum[c] / (n * sigma_ref);
  }
  return L;
}

}  // namespace lucent::render::detail
