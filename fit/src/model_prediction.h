// The predicted measurement pi L / P of a capture, per channel, for a bin or pixel footprint: the
// BSSRDF with both Fresnel transmittances (docs/DESIGN.md §6), averaged over the footprint by
// Gauss-Legendre quadrature. Templated for ceres::Jet.
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include "lucent/fit/fit.h"
#include "lucent/materials/dipole.h"
#include "lucent/materials/directional_dipole.h"
#include "lucent/materials/fresnel.h"
#include "lucent/materials/oblique.h"
#include "lucent/materials/tabulated.h"

namespace lucent::fit::detail {

/// Gauss-Legendre nodes and weights on [0, 1] for orders 1..8.
struct GaussLegendre {
  std::array<double, 8> node{}, weight{};
  int order = 1;
};
GaussLegendre gauss_legendre(int order);

/// The mean of at(px, py) over the square pixel of side `pixel` centred at (x, y), by
/// Gauss-Legendre in both directions; at(x, y) itself when `pixel` is 0 (a point).
template <typename T, typename F>
T footprint_mean(const F& at, double x, double y, double pixel, const GaussLegendre& gl) {
  if (!(pixel > 0)) return at(x, y);
  T sum(0);
  for (int a = 0; a < gl.order; ++a)
    for (int b = 0; b < gl.order; ++b)
      sum += gl.weight[a] * gl.weight[b] *
             at(x + (gl.node[a] - 0.5) * pixel, y + (gl.node[b] - 0.5) * pixel);
  return sum;
}

/// Geometry shared by every sample of one capture.
struct CaptureGeometry {
  double cos_incidence = 1;            ///< cos of the beam's polar angle
  double cos_view = 1;                 ///< cos of the camera's polar angle
  std::array<double, 3> w_i{0, 0, 1};  ///< unit, from the entry point toward the light
  /// The data are exitance (all directions), not pi L along the view direction.
  bool exitance = false;
  /// Per unit power incident on the sample (a camera), not per unit power entering it.
  bool per_incident_power = true;
  /// A slab of this thickness (mm; infinity: semi-infinite) seen from its lit side or, with
  /// `transmitted`, its far side: the tabulated model's SlabNodes.
  double thickness_mm = std::numeric_limits<double>::infinity();
  bool transmitted = false;
};

/// What multiplies the model's value (dipole R_d, ddipole pi S_d, the table's exitance or normal
/// radiance, all per unit power entering) to give the measured quantity. Per unit incident
/// power: the entry transmittance F_t(incidence). Exitance: nothing for the dipole (R_d is an
/// exitance) and the table; for the ddipole its outgoing hemispherical transmittance, pi S_d
/// integrated against F_t cos over the hemisphere: eta^2 (1 - F_dr(eta)) (transmittance from
/// inside is 1 - F_dr, from outside eta^2 times that). Radiance: the dipoles' outgoing
/// transmittance F_t(view); nothing for the table, whose radiance has it already.
template <typename T>
T fresnel_factor(const CaptureGeometry& g, const T& eta, FitModel model) {
  using materials::fresnel_transmittance;
  T front = g.per_incident_power ? fresnel_transmittance(T(g.cos_incidence), eta) : T(1);
  if (model == FitModel::kTabulated) return front;
  if (g.exitance) {
    return model == FitModel::kDirectionalDipole
               ? front * eta * eta * (T(1) - materials::diffuse_fresnel_reflectance(eta))
               : front;
  }
  return front * fresnel_transmittance(T(g.cos_view), eta);
}

/// The light scattered once from a normal pencil beam straight back along the normal (or, on a
/// slab's far side, straight on through it): a point at the entry (exit) point, which the
/// transport table, binned in radius, does not hold. A pencil beam leaves it inside the exclusion
/// radius; a beam of finite width spreads it into the shape of its footprint. Its pi L per unit
/// power entering, times the point's delta (per mm^2): pi omega p_HG(-1) T(1) / (2 eta^2)
/// (1 - e^(-2 sigma_t d)) on the lit side, pi omega p_HG(1) T(1) / eta^2 sigma_t d e^(-sigma_t d)
/// on the far side; exitance data hold none (once-scattered light leaves displaced).
template <typename T>
T single_scattering_point(const materials::Medium<T>& m, const CaptureGeometry& g) {
  using std::exp;
  if (g.exitance) return T(0);
  const T sigma_t = m.sigma_a + m.sigma_s;
  if (!(sigma_t > T(0))) return T(0);
  const T omega = m.sigma_s / sigma_t;
  const T transmit = materials::fresnel_transmittance(T(1), T(1) / m.eta) / (m.eta * m.eta);
  const auto hg = [&](const T& mu) {  // Henyey-Greenstein at cos theta = mu
    const T g2 = m.g * m.g;
    const T denom = T(1) + g2 - T(2) * m.g * mu;
    return (T(1) - g2) / (T(4 * std::numbers::pi) * denom * sqrt(denom));
  };
  const bool slab = g.thickness_mm < std::numeric_limits<double>::infinity();
  const T d = T(slab ? g.thickness_mm : 0.0);
  if (g.transmitted)
    return T(std::numbers::pi) * omega * hg(T(1)) * transmit * sigma_t * d * exp(-sigma_t * d);
  return T(std::numbers::pi) * omega * hg(T(-1)) * transmit / T(2) *
         (slab ? T(1) - exp(T(-2) * sigma_t * d) : T(1));
}

/// The table's quantity for the data's.
inline materials::TableQuantity table_quantity(const CaptureGeometry& g) {
  return g.exitance ? materials::TableQuantity::kExitance : materials::TableQuantity::kRadiance;
}

/// Standard dipole: mean of R_d over the annulus [r0, r1] (or R_d(r) when r0 == r1), per mm^2.
template <typename T>
T dipole_annulus(const materials::StandardDipole<T>& dipole, double r, double r0, double r1,
                 const GaussLegendre& gl) {
  if (!(r1 > r0)) return dipole.R_d(T(r));
  // Average over area: integral of 2 pi r R_d dr / (pi (r1^2 - r0^2)); nodes in r^2 so that the
  // weight is uniform in area.
  T sum(0);
  for (int k = 0; k < gl.order; ++k) {
    const double r_k = std::sqrt(r0 * r0 + gl.node[k] * (r1 * r1 - r0 * r0));
    sum += gl.weight[k] * dipole.R_d(T(r_k));
  }
  return sum;
}

/// Directional dipole at normal incidence on a plane: pi S_d averaged over the annulus.
template <typename T>
T ddipole_annulus(const materials::DirectionalDipole<T>& dd, double r, double r0, double r1,
                  const GaussLegendre& gl) {
  const materials::Vec3<T> up(T(0), T(0), T(1));
  const auto at = [&](double rr) {
    return T(std::numbers::pi) *
           dd.S_d(materials::Vec3<T>::Zero(), up, up, materials::Vec3<T>(T(rr), T(0), T(0)), up);
  };
  if (!(r1 > r0)) return at(r);
  T sum(0);
  for (int k = 0; k < gl.order; ++k) {
    sum += gl.weight[k] * at(std::sqrt(r0 * r0 + gl.node[k] * (r1 * r1 - r0 * r0)));
  }
  return sum;
}

/// Directional dipole for a square pixel centred at (x, y) of side `pixel` (0: the point), light
/// from w_i: pi S_d averaged over the footprint.
template <typename T>
T ddipole_pixel(const materials::DirectionalDipole<T>& dd, const CaptureGeometry& g, double x,
                double y, double pixel, const GaussLegendre& gl) {
  const materials::Vec3<T> up(T(0), T(0), T(1));
  const materials::Vec3<T> w_i(T(g.w_i[0]), T(g.w_i[1]), T(g.w_i[2]));
  const auto at = [&](double px, double py) {
    return T(std::numbers::pi) *
           dd.S_d(materials::Vec3<T>::Zero(), up, w_i, materials::Vec3<T>(T(px), T(py), T(0)), up);
  };
  return footprint_mean<T>(at, x, y, pixel, gl);
}

/// Standard dipole for a square pixel.
template <typename T>
T dipole_pixel(const materials::StandardDipole<T>& dipole, double x, double y, double pixel,
               const GaussLegendre& gl) {
  return footprint_mean<T>([&](double px, double py) { return dipole.R_d(T(std::hypot(px, py))); },
                          x, y, pixel, gl);
}

/// The tabulated model over an annulus (mean over area, nodes uniform in r^2) or at a point.
template <typename T>
T tabulated_annulus(const materials::TabulatedModel<T>& m, materials::TableQuantity q, double r,
                    double r0, double r1, const GaussLegendre& gl) {
  if (!(r1 > r0)) return m.at(q, T(r));
  T sum(0);
  for (int k = 0; k < gl.order; ++k)
    sum += gl.weight[k] * m.at(q, T(std::sqrt(r0 * r0 + gl.node[k] * (r1 * r1 - r0 * r0))));
  return sum;
}

/// The tabulated model over a square pixel footprint centred at (x, y).
template <typename T>
T tabulated_pixel(const materials::TabulatedModel<T>& m, materials::TableQuantity q, double x,
                  double y, double pixel, const GaussLegendre& gl) {
  return footprint_mean<T>([&](double px, double py) { return m.at(q, T(std::hypot(px, py))); },
                          x, y, pixel, gl);
}

/// Oblique incidence, the tabulated model's way (a Monte Carlo correction of the directional
/// dipole): the ddipole's pi S_d for light from w_i over a pixel footprint, each point multiplied
/// by the table's ratio to the ddipole at normal incidence at that radius, C(r) = table(r) /
/// (pi S_d,normal(r)). The ddipole carries the asymmetry of the oblique source; the table corrects
/// its level and radial shape, which are what it gets wrong (docs/DESIGN.md §4.1).
template <typename T>
T corrected_ddipole_pixel(const materials::TabulatedModel<T>& tab,
                          const materials::DirectionalDipole<T>& dd, materials::TableQuantity q,
                          const CaptureGeometry& g, double x, double y, double pixel,
                          const GaussLegendre& gl) {
  const materials::Vec3<T> up(T(0), T(0), T(1));
  const materials::Vec3<T> w_i(T(g.w_i[0]), T(g.w_i[1]), T(g.w_i[2]));
  const auto at = [&](double px, double py) {
    const double r = std::max(std::hypot(px, py), 1e-6);
    const T oblique = dd.S_d(materials::Vec3<T>::Zero(), up, w_i, materials::Vec3<T>(T(px), T(py), T(0)), up);
    const T normal = dd.S_d(materials::Vec3<T>::Zero(), up, up, materials::Vec3<T>(T(r), T(0), T(0)), up);
    if (!(normal > T(0))) return T(0);
    return oblique / normal * tab.at(q, T(r));
  };
  return footprint_mean<T>(at, x, y, pixel, gl);
}

/// Oblique incidence with an oblique table slice at the capture's incidence (exact to transport):
/// the table's 2D profile over a square pixel footprint centred at (x, y), the position turned
/// into the beam's frame (travelling toward +x: the horizontal part of -w_i).
template <typename T>
T oblique_pixel(const materials::ObliqueModel<T>& m, materials::TableQuantity q,
                const CaptureGeometry& g, double x, double y, double pixel,
                const GaussLegendre& gl) {
  double tx = -g.w_i[0], ty = -g.w_i[1];
  const double len = std::hypot(tx, ty);
  if (len > 0) tx /= len, ty /= len;
  else tx = 1, ty = 0;
  const auto at = [&](double px, double py) {
    return m.at(q, px * tx + py * ty, -px * ty + py * tx);
  };
  // The beam's single-scattering line, where it crosses the pixel (not a quadrature's business).
  return footprint_mean<T>(at, x, y, pixel, gl) + m.line_in_square(q, x - 0.5 * pixel, x + 0.5 * pixel, y - 0.5 * pixel,
                                y + 0.5 * pixel, tx, ty);
}

/// One sample's model value (before fresnel_factor): a radial bin (annulus, or a pixel footprint
/// at the bin's radius when `pixel` > 0 and not `radial`) or a 2D pixel.
template <typename T>
T model_value(FitModel model, const materials::TabulatedProfile* table,
              const materials::Medium<T>& medium, const CaptureGeometry& g, bool radial, double r,
              double r0, double r1, double x, double y, double pixel, const GaussLegendre& gl) {
  switch (model) {
    case FitModel::kDipole: {
      const materials::StandardDipole<T> dipole(medium);
      return radial ? dipole_annulus(dipole, r, r0, r1, gl) : dipole_pixel(dipole, x, y, pixel, gl);
    }
    case FitModel::kTabulated: {
      const materials::TableQuantity q = table_quantity(g);
      if (!radial && g.cos_incidence < 0.9999 && table->oblique())
        return oblique_pixel(materials::ObliqueModel<T>(*table->oblique(), medium), q, g, x, y,
                             pixel, gl);
      const materials::TabulatedModel<T> tab(*table, medium, g.thickness_mm, g.transmitted);
      if (!radial && g.cos_incidence < 0.9999)
        return corrected_ddipole_pixel(tab, materials::DirectionalDipole<T>(medium), q, g, x, y,
                                       pixel, gl);
      return radial ? tabulated_annulus(tab, q, r, r0, r1, gl)
                    : tabulated_pixel(tab, q, x, y, pixel, gl);
    }
    default: {
      const materials::DirectionalDipole<T> dd(medium);
      return radial ? ddipole_annulus(dd, r, r0, r1, gl) : ddipole_pixel(dd, g, x, y, pixel, gl);
    }
  }
}

}  // namespace lucent::fit::detail
