// The subsurface form factor of Mertens et al. (Mertens et al. 2003, §4): the integral of the
// standard dipole's R_d(x_i, x_o) over a planar polygon A, F(A, x_o) = integral over A of R_d dx_i
// (mm^-2 x mm^2: dimensionless), so that B(x_o) = sum_k E_k F(A_k, x_o).
//
// Each source of the dipole (prefactor z, at height H above the polygon's plane, its foot the
// "pole" p in that plane) contributes I = integral over A of z (1 + sigma s) e^(-sigma s) / s^3 dx,
// s^2 = |x - p|^2 + H^2, sigma = sigma_tr. In polar coordinates about p the radial integral is
// exact (d/ds of -e^(-sigma s) / s is (1 + sigma s) e^(-sigma s) / s^2, and s ds = r dr), and what
// remains is a sum over the polygon's oriented edges of
//   Gamma_e = I1 - I2,  I1 = z e^(-sigma H) / H dtheta_e,
//   I2 = z R integral over the edge of e^(-sigma s) / (s (R^2 + t^2)) dt        (eqs. 10-13),
// with dtheta_e the signed angle the edge subtends at p and R the signed distance from p to the
// edge's line. The text's "I_e = I1 + I2" is a misprint (eq. 10 subtracts), eq. 18 sums the real
// and the virtual source (I'_a + I''_a), and eq. 16's first-order term misses a factor 1/2 (it only
// matters beyond the midpoint rule). Shared edges of coplanar faces cancel, so a cluster's form
// factor is its boundary's edge sum.
//
// I2 per edge: the seed expands the integrand about each segment's midpoint and keeps the zeroth
// order, I2 ~ z R e^(-sigma s0) L / (r0^2 s0) (eq. 17), splitting the edge until L / r0 < 2/5 and
// L sigma < 2/5 (eq. 19). lucent keeps that rule (`kSeedMidpoint`) and adds a two-point
// Gauss-Legendre rule per segment (`kGauss2`, an extension: the same subdivision, one more
// evaluation, error O(L^4) instead of O(L^2)); the constant is a knob.
//
// Where the dipole sits (the "decide"): lucent's R_d takes the chord distance,
// s = sqrt(|x_i - x_o|^2 + z^2) (the planar dipole evaluated at the 3D distance), which for a
// polygon whose plane is h_o from x_o is exactly the polar integral with the pole at x_o's foot and
// H = sqrt(h_o^2 + z^2) >= z > 0 (`kChord`, default: the renderer's other techniques and the
// reference use the same R_d, so errors are the technique's own). The seed places the sources in
// 3D at x_o -/+ z N_o (`kSeed3d`), which differs by 4-8% on curved meshes and can put a source on a
// polygon's plane (H -> 0): its H is floored at 1e-3 z_r there (a guard, named).
#pragma once

#include <array>
#include <span>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "lucent/materials/medium.h"

namespace lucent::render::hierarchical {

using Vec2d = Eigen::Vector2d;
using Vec3d = Eigen::Vector3d;

enum class SegmentRule { kSeedMidpoint, kGauss2 };
enum class DipolePlacement { kChord, kSeed3d };

SegmentRule parse_segment_rule(const std::string& text);            ///< midpoint | gauss2
DipolePlacement parse_dipole_placement(const std::string& text);    ///< chord | seed
std::string to_string(SegmentRule rule);
std::string to_string(DipolePlacement placement);

struct FormFactorOptions {
  /// Split an edge segment until L / r0 < c and (when `global_condition`) L sigma_tr < c; the
  /// seed's c is 2/5 (eq. 19).
  double edge_constant = 0.4;
  bool global_condition = true;
  SegmentRule rule = SegmentRule::kGauss2;
  DipolePlacement placement = DipolePlacement::kChord;
  /// Subdivision depth cap: a pole on (or within 1e-12 of) an edge's line inside the segment makes
  /// L / r0 unbounded; the cap ends the recursion there (the edge's exact limit is then 0 anyway,
  /// its wedge having no area).
  int max_depth = 40;
};

struct FormFactorCounters {
  long calls = 0;     ///< form factors evaluated (polygons)
  long segments = 0;  ///< edge segments integrated (the seed's "samples", Figure 4)
};

/// One source of the dipole seen from a plane: its prefactor z (mm), height H (mm), pole (2D).
struct PlaneSource {
  double z = 0, H = 0;
  Vec2d pole = Vec2d::Zero();
};

/// A plane's orthonormal frame: origin, tangents u, v and normal n = u x v.
struct PlaneFrame {
  Vec3d origin = Vec3d::Zero(), u = Vec3d::UnitX(), v = Vec3d::UnitY(), n = Vec3d::UnitZ();
  static PlaneFrame from_normal(const Vec3d& origin, const Vec3d& normal);
  Vec2d project(const Vec3d& x) const { return {(x - origin).dot(u), (x - origin).dot(v)}; }
};

/// The two sources (real, virtual) of the dipole at receiver (x_o, n_o), seen from `plane`.
void dipole_sources(const materials::DiffusionCoefficients<double>& c, const Vec3d& x_o,
                    const Vec3d& n_o, const PlaneFrame& plane, DipolePlacement placement,
                    PlaneSource out[2]);

/// Gamma_e = I1 - I2 of one source for the oriented edge a -> b in the plane (z included).
double edge_term(const PlaneSource& source, double sigma_tr, const Vec2d& a, const Vec2d& b,
                 const FormFactorOptions& options, FormFactorCounters* counters);

/// F(A, x_o) for a polygon given as oriented 2D edges in `plane` (closed loops, counter-clockwise
/// about plane.n; holes clockwise): alpha' / (4 pi) x the sum over both sources and all edges.
double edges_form_factor(const materials::DiffusionCoefficients<double>& c, const Vec3d& x_o,
                         const Vec3d& n_o, const PlaneFrame& plane,
                         std::span<const Vec2d> edge_starts, std::span<const Vec2d> edge_ends,
                         const FormFactorOptions& options, FormFactorCounters* counters = nullptr);

/// edges_form_factor of the three colour channels at once, bit for bit the same values and
/// counts: with the chord placement their six sources share the pole, so each edge's geometry,
/// angle and subdivision traversal are computed once (a channel's own L sigma_tr < c still decides
/// where it stops splitting); other placements call edges_form_factor per channel.
std::array<double, 3> edges_form_factor_rgb(
    const std::array<materials::DiffusionCoefficients<double>, 3>& c, const Vec3d& x_o,
    const Vec3d& n_o, const PlaneFrame& plane, std::span<const Vec2d> edge_starts,
    std::span<const Vec2d> edge_ends, const FormFactorOptions& options,
    FormFactorCounters* counters = nullptr);

/// F(triangle abc, x_o): the triangle's own plane, its winding (a, b, c) giving the normal.
double triangle_form_factor(const materials::DiffusionCoefficients<double>& c, const Vec3d& x_o,
                            const Vec3d& n_o, const Vec3d& a, const Vec3d& b, const Vec3d& v_c,
                            const FormFactorOptions& options,
                            FormFactorCounters* counters = nullptr);

/// The single-sample estimate of far links: area x R_d(x_o, midpoint), with the sources placed as
/// `placement` says (kChord: the chord distance, lucent's R_d).
double point_form_factor(const materials::DiffusionCoefficients<double>& c, const Vec3d& x_o,
                         const Vec3d& n_o, const Vec3d& midpoint, double area,
                         DipolePlacement placement = DipolePlacement::kChord);

}  // namespace lucent::render::hierarchical
