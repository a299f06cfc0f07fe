// How the shape of an object changes multiple scattering between two surface points (lucent;
// docs/DESIGN.md §4.4). The radial BSSRDFs (tabulated, dipole) are profiles of a plane: R(r) for
// light entering and leaving one flat face r apart. On a curved object the exit point is off the
// entry point's plane: on a convex one the surface turns toward the light diffusing from the entry
// (near it, a photon under the tangent plane is closer to the surface than on a plane), and the
// light that goes deep is not lost to an unbounded half-space but comes back out; on a concave one
// the reverse. Diffusion theory says how much: the factor is G = J_shape / J_plane, the flux a
// diffusion source makes through the exit surface on the shape over that on a plane at the same
// chord r = |x_o - x_i|, which carries the shape over to any radial profile (the transport table
// included) and is exactly 1 on a plane, where the table is exact.
//
// The shape is the sphere that osculates the pair: the one through x_i and x_o with normals n_i and
// n_o there (exact for a sphere: x_o - x_i = a (n_o - n_i)), its curvature in the least-squares
// sense 1/a = (x_o - x_i).(n_o - n_i) / r^2 (negative: concave; 0: a plane, or a twist the chord
// does not see). In a sphere of radius a a point source at radius r_0 with the fluence held at 0 on
// the extrapolated sphere R_e = a + z_b (z_b = 2 A D) has, for diffusion without absorption,
// exactly one image: Kelvin's, at R_e^2 / r_0 on the same ray, of strength -R_e / r_0; with
// absorption it is the standard approximation and tends to the plane's dipole as a grows. Each
// source's flux through the sphere at chord r is
//   J = q f(d) (x_o - s) . n_o,  f(d) = (1 + sigma_tr d) e^(-sigma_tr d) / d^3.
// The source is not a point at z_r = 1 / sigma_t' as in the dipole but the beam's own depth
// distribution, sigma_t' e^(-sigma_t' z): three Gauss-Laguerre depths t_k / sigma_t' (weights w_k,
// mean z_r) along the refracted beam (the normal for a normal beam), each with its image, in both
// the sphere's sum and the plane's, kept within 0.9 of the way to the beam's closest approach to the
// centre (0.9 a for a normal beam). The point source misses a tenth near the entry.
//
// In the entry point's frame (origin x_i, z along n_i, the sphere's centre at -a z) everything is a
// function of r and 1/a (and the beam's direction), with no difference of large numbers as a
// grows: the exit point is (r cos(g/2), 0, -r sin(g/2)) with sin(g/2) = r / (2 a), its normal at
// angle g from z; for a normal beam the image of depth z sits at s = (2 z_b + z_b^2 / a + z) /
// (1 - z / a) on the axis with strength -(1 + z_b / a) / (1 - z / a) (one_way_in_frame has the
// general form). With normal beams G depends on the pair only through r and 1/a, both symmetric in
// the two points; with oblique ones it is the geometric mean of the two beams' one-way factors:
// reciprocal either way.
//
// Against Monte Carlo of a normal beam into spheres of 1.5-10 mean free paths (isotropic, Fresnel
// boundary, eta 1-1.5, alpha' 0.8-0.999; notebooks_data/bench/sphere_factor_mc.md, written
// independently in numpy): within 17% of the true R_sphere(r) / R_plane(r) to 2 mean free paths
// from the entry, 35% to 4 (tests/render/geometry_factor_test.cpp), where the former
// modified-tangent-plane factor gave 1.12 for a true 1.32 at one mean free path on a sphere of 3.4
// and was 41% short at 3.4 (alpha' 0.8).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "lucent/materials/material.h"
#include "lucent/materials/medium.h"
#include "lucent/materials/profile_table.h"

namespace lucent::materials {

/// Whether the factor applies to `model`: the radial models (tabulated, dipole); the directional
/// dipole places its own sources with both normals.
inline bool geometry_factor_applies(DiffusionModel model) {
  return model != DiffusionModel::kDirectionalDipole;
}

/// Gauss-Laguerre nodes and weights (3 points) for the beam's depths, in mean free paths (4 points
/// moved G by a few per cent and cost the maps' gather a third more).
inline constexpr std::array<double, 3> kBeamDepths = {0.4157745567834791, 2.294280360279042,
                                                      6.289945082937479};
inline constexpr std::array<double, 3> kBeamDepthWeights = {0.7110930099291730, 0.2785177335692408,
                                                            0.01038925650158614};

template <typename T>
class GeometryFactor {
 public:
  using Vec3 = Eigen::Matrix<T, 3, 1>;
  /// The largest factor taken (so that a mesh's folds and seams cannot make a firefly).
  static constexpr double kMax = 64;

  explicit GeometryFactor(const DiffusionCoefficients<T>& c) : c_(c) {}

  /// G for light entering at x_i (outward unit normal n_i) and leaving at x_o (n_o), mm, both
  /// beams normal to the surface (then either one-way factor is the pair's: reciprocal as it is).
  T operator()(const Vec3& x_i, const Vec3& n_i, const Vec3& x_o, const Vec3& n_o) const {
    return from_entry(x_i, n_i, Vec3::Zero(), x_o, n_o);
  }

  /// G for a beam entering at x_i whose refracted direction's tangential part is d_i
  /// (oblique_displacement(w_i, n_i, eta); 0 at normal incidence) and light leaving at x_o toward
  /// a view whose reversed ray's is d_o: the sources lie along each refracted beam, so that a beam
  /// entering obliquely crosses the sphere along its chord instead of going deep (at eta 1 a beam
  /// at 70 degrees comes out on a short chord: the normal beam's far-field gain, 1.3-18x at 5-10
  /// mean free paths on a sphere of 5, is 0.8-2.5x by Monte Carlo). Reciprocal: the geometric mean
  /// of the two one-way factors, each with its own beam.
  T operator()(const Vec3& x_i, const Vec3& n_i, const Vec3& d_i, const Vec3& x_o, const Vec3& n_o,
               const Vec3& d_o) const {
    if (!c_.scatters()) return T(1);
    const Vec3 x = x_o - x_i;
    const T r2 = x.squaredNorm();
    if (!(r2 > T(1e-12) * c_.z_r * c_.z_r)) return T(1);
    const T inv_a = x.dot(n_o - n_i) / r2;
    return std::sqrt(one_way(x, n_i, d_i, inv_a) * one_way(Vec3(-x), n_o, d_o, inv_a));
  }

  /// The entry's one-way factor alone, g(i -> o; d_i): the maps' form (their gather does not know
  /// the exit's view; GLSL twin geometry_factor.glsl). Not reciprocal.
  T from_entry(const Vec3& x_i, const Vec3& n_i, const Vec3& d_i, const Vec3& x_o,
               const Vec3& n_o) const {
    if (!c_.scatters()) return T(1);
    const Vec3 x = x_o - x_i;
    const T r2 = x.squaredNorm();
    if (!(r2 > T(1e-12) * c_.z_r * c_.z_r)) return T(1);
    return one_way(x, n_i, d_i, x.dot(n_o - n_i) / r2);
  }

  /// One way, from the entry (at the origin, normal n, beam d) to the exit x away.
  T one_way(const Vec3& x, const Vec3& n, const Vec3& d, T inv_a) const {
    using std::sqrt;
    // The frame: n up, t along the exit's tangential direction (the beam's where there is none).
    Vec3 t = x - x.dot(n) * n;
    if (!(t.squaredNorm() > T(1e-20) * x.squaredNorm())) t = d - d.dot(n) * n;
    if (!(t.squaredNorm() > T(1e-30))) t = n.unitOrthogonal();
    t.normalize();
    const Vec3 b = n.cross(t);
    const T d_t = d.dot(t), d_b = d.dot(b);
    const T cos_t = sqrt(std::max(T(1) - d_t * d_t - d_b * d_b, T(0)));
    return one_way_in_frame(x.norm(), clamp_curvature(inv_a), d_t, d_b, cos_t);
  }

 private:
  // Tighter than a mean free path (convex) or than twice the extrapolation distance (concave), the
  // sphere is not a diffusion problem: held there.
  T clamp_curvature(T inv_a) const {
    const T z_b = T(0.5) * (c_.z_v - c_.z_r);
    return std::clamp(inv_a, T(-0.5) / z_b, T(1) / c_.z_r);
  }

  // The beam along (w_t, w_b, -cos_t) in the entry's frame (t toward the exit, n up); the exit at
  // chord r on the sphere of curvature inv_a: (r cos(g/2), 0, -r sin(g/2)), its normal
  // (sin g, 0, cos g); the plane's exit at (r, 0, 0), normal up. Each source (at path length s
  // along the beam, u = s w) has its image: the plane's mirror about z = z_b, the sphere's Kelvin
  // image at centre + (R_e / |u - centre|)^2 (u - centre), of strength R_e / |u - centre|, which
  // in the frame (no centre a away: no large differences as a grows) is
  //   rho u + (2 z_b + z_b^2 / a - 2 u_n - s^2 / a) / den up,  den = 1 + 2 u_n / a + s^2 / a^2,
  //   rho = (1 + z_b / a)^2 / den, strength (1 + z_b / a) / sqrt(den).
  T one_way_in_frame(T r, T inv_a, T w_t, T w_b, T cos_t) const {
    using std::sqrt;
    if (!(r > T(0)) || !(inv_a != T(0))) return T(1);
    const T z_b = T(0.5) * (c_.z_v - c_.z_r);
    const T half_sin = std::clamp(r * inv_a / T(2), T(-1), T(1));  // sin(g / 2)
    const T half_cos = sqrt(T(1) - half_sin * half_sin);
    const T sin_g = T(2) * half_sin * half_cos, cos_g = T(1) - T(2) * half_sin * half_sin;
    const T x_t = r * half_cos, x_n = -r * half_sin;
    // The sources are kept within 0.9 of the beam's way to its closest approach to the sphere's
    // centre (half its chord), where the image would leave for infinity.
    const T reach = inv_a > T(0) ? T(0.9) * cos_t / inv_a : T(std::numeric_limits<double>::max());
    const T s0 = c_.sigma_tr * r;  // e^(-s0): the scale both sums share, left out of both
    const T lift = T(1) + z_b * inv_a;
    T sphere(0), plane(0);
    for (std::size_t k = 0; k < kBeamDepths.size(); ++k) {
      const T s = std::min(T(kBeamDepths[k]) * c_.z_r, reach);
      const T u_t = s * w_t, u_b = s * w_b, u_n = -s * cos_t;
      const T w(kBeamDepthWeights[k]);
      const T lateral = (r - u_t) * (r - u_t) + u_b * u_b;
      const T above = T(2) * z_b - u_n;
      plane +=
          w * (-u_n * term(lateral + u_n * u_n, s0) + above * term(lateral + above * above, s0));
      const T den = T(1) + T(2) * u_n * inv_a + s * s * inv_a * inv_a;
      const T rho = lift * lift / den;
      const T i_t = rho * u_t, i_b = rho * u_b;
      const T i_n = rho * u_n + (T(2) * z_b + z_b * z_b * inv_a - T(2) * u_n - s * s * inv_a) / den;
      const T e_t = x_t - u_t, e_n = x_n - u_n, f_t = x_t - i_t, f_n = x_n - i_n;
      sphere += w * (term(e_t * e_t + u_b * u_b + e_n * e_n, s0) * (e_t * sin_g + e_n * cos_g) -
                     lift / sqrt(den) * term(f_t * f_t + i_b * i_b + f_n * f_n, s0) *
                         (f_t * sin_g + f_n * cos_g));
    }
    if (!(plane > T(0))) return T(1);
    return std::clamp(sphere / plane, T(0), T(kMax));
  }

  // f(d) e^(s0) = (1 + s) e^(s0 - s) / d^3 with s = sigma_tr d.
  T term(T d2, T s0) const {
    using std::exp;
    using std::sqrt;
    const T d = sqrt(std::max(d2, T(1e-20)));
    const T s = c_.sigma_tr * d;
    return (T(1) + s) * exp(s0 - s) / (d2 * d);
  }

  DiffusionCoefficients<T> c_;
};

}  // namespace lucent::materials
