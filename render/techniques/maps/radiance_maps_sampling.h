// The CPU side of the radiance-map technique's sampling (Dal Corso 2014 §5.3.4): Halton points, the
// K camera directions on the sphere, the exponentially biased disc and its weights, and the cameras
// fitted to the mesh. No OpenGL here, so tests/render/radiance_maps_test.cpp checks it directly.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "lucent/materials/material.h"
#include "lucent/render/render_settings.h"
#include "lucent/render/scene.h"

namespace lucent::render::detail {

using Mat4f = Eigen::Matrix4f;

/// Van der Corput radical inverse Phi_b(n) (seed Listing 5.6), in [0, 1).
double radical_inverse(unsigned index, unsigned base);

/// K unit directions: Halton points (bases 2, 3) n = 1..K mapped to the sphere by the
/// area-preserving z = 2t - 1, phi = 2 pi s (seed §5.3.4). n = 0, the pole (0, 0, -1) alone, is
/// skipped.
std::vector<Vec3f> halton_sphere_directions(int count);

/// sigma* = min over channels of sigma_tr / q (seed §5.3.4.1, §6.2.1), mm^-1. Channels that do not
/// absorb (sigma_tr = 0) are skipped; 0 when none absorbs (uniform disc).
double sigma_star(const materials::Material& material, double q);

struct DiscSample {
  float x_mm = 0, y_mm = 0;  ///< offset in the disc plane, mm
  float weight_mm2 = 0;      ///< the sample's share of the disc area, bias undone, mm^2
};

struct DiscSamples {
  std::vector<DiscSample> samples;  ///< light l's share: [light_offset[l], + light_count[l])
  std::vector<int> light_offset, light_count;
  double sigma_star_per_mm = 0;  ///< sigma*
  double disc_radius_mm = 0;     ///< radius the M points were drawn in
  double used_radius_mm = 0;     ///< rho: radius of the disc the N kept points stand for
  long candidates = 0;           ///< Halton points tried by the rejection
  std::string to_string() const;
};

/// The M points of the disc, sorted by radius (see exponential_disc_samples). Drawing them is the
/// expensive part (rejection: up to ~450,000 Halton candidates for M = 1000 when sigma* R is large,
/// tens of ms), so the renderer draws them once per material, disc and lights and only re-selects
/// per frame.
struct DiscPoints {
  struct Point {
    double x, y, r;  ///< mm
    double weight_mm2 = 0;  ///< the point's share of the disc in the quadrature of all M, mm^2
    double cdf = 0;         ///< fraction of the sampling density below r (for kNearest)
  };
  std::vector<Point> points;
  double sigma_star_per_mm = 0, disc_radius_mm = 0;
  long candidates = 0;
  DiscDistribution distribution = DiscDistribution::kExponential;
};
DiscPoints exponential_disc_points(int M, double sigma_star_per_mm, double disc_radius_mm,
                                   const Eigen::Vector3d& shift = Eigen::Vector3d::Zero());
/// The disc of DiscDistribution::kProfile: M radii at the stratified quantiles (j + s) / M of the
/// channels' mean profile density p_A (RadialProfileDensity, profile_sampling.h: out to
/// disc_radius_mm or the widest channel's reach), angles 2 pi frac(j / phi + s'), (s, s') =
/// (0.5, 0) shifted by `shift` modulo 1; weights 1 / (M p_A(r)), the exact inverse of the density
/// the radii were drawn from. The M points are a quadrature of the disc integral of any function,
/// and for the profile itself a near-constant integrand.
DiscPoints profile_disc_points(int M, const materials::Material& material,
                               materials::DiffusionModel model, double disc_radius_mm,
                               const Eigen::Vector3d& shift = Eigen::Vector3d::Zero());

/// This frame's N of the points and their weights (see exponential_disc_samples).
DiscSamples select_disc_samples(const DiscPoints& disc, int N, int lights,
                                DiscSelection selection = DiscSelection::kNearest, int frame = 1);

/// The disc of seed §5.3.4.1: M Halton points (bases 2, 3) uniform on the disc of radius R (mapped
/// by r = R sqrt(s), which is area-uniform; the seed's "project the sphere point" is not, its
/// density grows toward the rim), each kept with probability e^(-sigma* r) (rejection against a
/// third Halton dimension, base 5, instead of the seed's rand()), until M are kept. Of these the N
/// nearest the centre are used (the seed: "only the N points closest to x_o"), standing for the
/// disc of radius rho = midway between the N-th and (N+1)-th radius (R when N = M), shared
/// round-robin by `lights` lights (N / L each, seed §5.5.1). Weights: light l's n_l points carry
///   w_i = Z(rho) e^(sigma* r_i) / n_l,  Z(rho) = integral of e^(-sigma* r) over the disc of radius
///   rho
///       = 2 pi / sigma*^2 (1 - e^(-sigma* rho) (1 + sigma* rho)),
/// the importance-sampling estimate of the disc integral (the kept points are distributed as
/// e^(-sigma* r) / Z(rho) on that disc). The seed's A_c / N e^(sigma* r_i) takes the mean of
/// e^(sigma* r) to be 1; it is pi rho^2 / Z(rho), so the seed's images are brighter by that factor
/// unless it is absorbed in the light's units. (Normalising by the sample mean of e^(sigma* r)
/// instead, exact for a constant integrand, was tried and dropped: e^(sigma* r) is heavy-tailed and
/// its mean from a few dozen points is off by factors.) Guard: R is capped at 30 / sigma*
/// (e^-30 of the centre's density) so the rejection ends for strongly absorbing media.
/// `shift` (each in [0, 1)) moves the three Halton coordinates modulo 1 (a Cranley-Patterson
/// rotation): shift 0 is the seed's fixed set; a different shift per frame gives every frame new
/// radii (RadianceMapOptions::new_radii_each_frame).
///
/// DiscSelection::kStrata (an extension, lucent's default) instead splits the M radius-sorted points
/// into N strata of M/N consecutive radii and uses one point of each per frame, frame t the
/// ((t - 1) mod size)-th of its stratum, weighted w_i = Z(R) e^(sigma* r_i) size_i / M (times
/// N / n_l for light l's share): every frame is an estimate of the whole disc's integral, and after
/// M/N frames every point has been used once, so the accumulation converges to the seed's N = M
/// image (its closest to the path-traced reference, §6.2.2) at the cost of N per frame. With L
/// lights sharing the N, stratum i goes to light (i + t - 1) mod L and the point within a stratum
/// advances every L frames: L M / N frames gather every point for every light.
DiscSamples exponential_disc_samples(int M, int N, double sigma_star_per_mm, double disc_radius_mm,
                                     int lights,
                                     const Eigen::Vector3d& shift = Eigen::Vector3d::Zero(),
                                     DiscSelection selection = DiscSelection::kNearest,
                                     int frame = 1);

/// The shift of frame t (1-based; frame 1 unshifted): the additive recurrence t * (1/phi_3,
/// 1/phi_3^2, 1/phi_3^3), phi_3 the plastic number (a low-discrepancy sequence in 3D, Roberts
/// 2018).
Eigen::Vector3d frame_shift(int t);

/// A camera of a layer or a light: world (mm) -> clip.
struct LayerCamera {
  Mat4f view_proj = Mat4f::Identity();
  Vec3f direction{0, 0, 1};  ///< unit, from the object toward the camera (orthographic) or light
  float near_mm = 0, far_mm = 0;
  float extent_mm = 0;  ///< orthographic: width of the view, mm
  float extent_per_mm = 0;  ///< perspective: width of the view per mm of distance (2 tan half-angle)
};

/// Orthographic camera looking at `centre` from direction `toward_camera`, covering the sphere of
/// `radius_mm` (seed: "orthographic, fitted to the bounds").
LayerCamera fitted_orthographic(const Vec3f& centre, float radius_mm, const Vec3f& toward_camera);

/// Perspective camera at `eye` looking at `centre`, its square frustum just containing the sphere
/// (half-angle asin(radius / distance)); a light inside or near the sphere gets a 150 degree
/// frustum, and surface outside it is unlit.
LayerCamera fitted_perspective(const Vec3f& centre, float radius_mm, const Vec3f& eye);
/// The light camera at a point `eye` of an area light emitting toward `normal`: fitted_perspective
/// from outside the bounding sphere; from inside it (a lamp close to a large object), 150 degrees
/// about the emitting direction (the half-space behind the polygon gets no light).
LayerCamera fitted_area_perspective(const Vec3f& centre, float radius_mm, const Vec3f& eye,
                                    const Vec3f& normal);

/// The viewer's perspective camera with near and far planes around the sphere.
Mat4f camera_view_proj(const Camera& camera, const Vec3f& centre, float radius_mm);

/// Blur level for frame t of T: min(max_level, ceil(log4(T / t))), 0 from t >= T. Each level
/// averages about four texels, cutting the variance by four, so the level compensates the 1/t of
/// the accumulation: the noise stays at about that of the converged maps (seed §6.2.4: strong blur
/// at first, none at convergence).
int blur_level_for_frame(int t, int T, int max_level);

}  // namespace lucent::render::detail
