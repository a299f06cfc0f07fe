// What the CPU reference's two samplers share (reference_renderer.cpp: uniform area samples with
// clusters; reference_probes.cpp: probe rays importance-sampling the profile around each pixel):
// the per-channel BSSRDF, pixel hits (threads, random numbers and the Embree scene: ray_scene.h).
#pragma once

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <numbers>
#include <thread>
#include <vector>

#include <Eigen/Geometry>

#include "lucent/core/error.h"
#include "lucent/materials/angular.h"
#include "lucent/materials/dipole.h"
#include "lucent/materials/directional_dipole.h"
#include "lucent/materials/fresnel.h"
#include "lucent/materials/geometry_factor.h"
#include "lucent/materials/tabulated.h"
#include "lucent/render/reference_renderer.h"
#include "lucent/render/scene.h"
#include "ray_scene.h"

namespace lucent::render::detail {

// ---------------------------------------------------------------------------------------------
// The BSSRDF per channel, in double.

class ChannelBssrdf {
 public:
  /// `geometry`: the radial models take the shape's factor (materials/geometry_factor.h);
  /// `skewed`: they take the oblique beams' skew (materials::oblique_skew) of the entry along w_i
  /// and of the exit along w_o.
  ChannelBssrdf(const materials::Medium<double>& medium, DiffusionModel model,
                bool geometry = false, bool skewed = false)
      : model_(model),
        dipole_(medium),
        ddipole_(medium),
        geometry_(derive_coefficients(medium)),
        use_geometry_(geometry && materials::geometry_factor_applies(model)),
        eta_(medium.eta) {
    const auto coefficients = derive_coefficients(medium);
    skewed_ =
        skewed && materials::angular_factor_applies(model) && coefficients.sigma_t_reduced > 0;
    if (skewed_) {
      mean_free_path_ = 1 / coefficients.sigma_t_reduced;
      sigma_tr_ = coefficients.sigma_tr;
    }
    if (model == DiffusionModel::kTabulated) {
      profile_ = materials::cached_tabulated_profile(materials::default_transport_table(),
                                                     medium.g, medium.eta);
      tabulated_ = std::make_shared<materials::TabulatedModel<double>>(*profile_, medium);
    }
  }

  /// Whether S_d depends on w_i (so that each light needs its own evaluation).
  bool depends_on_light() const { return model_ == DiffusionModel::kDirectionalDipole || skewed_; }

  /// S_d per mm^2 per sr without Fresnel; w_i (toward the light) and w_o (toward the eye; zero:
  /// none) are ignored by the radial models unless skewed (the tabulated one's is
  /// TabulatedModel::S_d), n_i and n_o too unless they take the shape's factor.
  double operator()(const Vec3d& x_i, const Vec3d& n_i, const Vec3d& w_i, const Vec3d& x_o,
                    const Vec3d& n_o, const Vec3d& w_o = Vec3d::Zero()) const {
    if (model_ == DiffusionModel::kDirectionalDipole) return ddipole_.S_d(x_i, n_i, w_i, x_o, n_o);
    const double r = (x_o - x_i).norm();
    double s_d = model_ == DiffusionModel::kDipole ? dipole_.S_d(r) : tabulated_->S_d(r);
    if (!skewed_) return use_geometry_ && s_d > 0 ? s_d * geometry_(x_i, n_i, x_o, n_o) : s_d;
    // The beams' refracted directions (tangential parts) skew the profile and, with the shape's
    // factor, place its sources.
    const Vec3d d_i = materials::oblique_displacement(w_i, n_i, eta_);
    const Vec3d d_o = materials::oblique_displacement(w_o, n_o, eta_);
    s_d *= materials::oblique_skew(Vec3d(x_o - x_i), Vec3d(d_i - d_o), mean_free_path_, sigma_tr_);
    return use_geometry_ && s_d > 0 ? s_d * geometry_(x_i, n_i, d_i, x_o, n_o, d_o) : s_d;
  }

 private:
  DiffusionModel model_;
  materials::StandardDipole<double> dipole_;
  materials::DirectionalDipole<double> ddipole_;
  materials::GeometryFactor<double> geometry_;
  bool use_geometry_;
  double eta_;
  bool skewed_ = false;                       ///< the oblique beam's skew (materials::oblique_skew)
  double mean_free_path_ = 0, sigma_tr_ = 0;  ///< 1 / sigma_t' (mm), mm^-1
  std::shared_ptr<const materials::TabulatedProfile> profile_;
  std::shared_ptr<const materials::TabulatedModel<double>> tabulated_;
};

/// The scene's three channels' BSSRDFs for `model` (Scene::geometry_factor; the oblique skew
/// with Scene::angular).
inline std::array<ChannelBssrdf, 3> channel_bssrdfs(const Scene& scene, DiffusionModel model) {
  const auto channel = [&](int c) {
    return ChannelBssrdf(scene.material.medium(c), model, scene.geometry_factor,
                         scene.angular && scene.oblique_skew);
  };
  return {channel(0), channel(1), channel(2)};
}

/// The direction w from x toward a light, the falloff 1 / distance^2 of a point light (1 for a
/// directional one) and the distance (infinite for a directional light); false at the light.
inline bool toward_light(const Light& light, const Vec3f& x, Vec3f& w, double& falloff,
                         double& distance) {
  falloff = 1;
  distance = kInf;
  if (light.type == LightType::kDirectional) {
    w = light.direction.normalized();
    return true;
  }
  const Vec3f to_light = light.position - x;
  distance = to_light.norm();
  if (!(distance > 0)) return false;
  w = to_light / float(distance);
  falloff = 1.0 / (distance * distance);
  return true;
}

struct PixelHit {
  Vec3f x_o, n_o;
  double fresnel_out = 0;  ///< F_t(eta, n_o . w_o)
  double fresnel_reflect = 0;
  Vec3f reflected = Vec3f::Zero();
  Vec3f w_o = Vec3f::Zero();  ///< toward the eye
  Vec3f g_o = Vec3f::Zero();  ///< geometric normal (shadow-ray offset)
};

/// One pass of the probe-ray sampler (reference_probes.cpp): for each object pixel i, the
/// subsurface radiance before the outgoing Fresnel factor, added to accumulated[i].
/// Every light's specular lobe at a pixel's point, with shadow rays (reference_specular.cpp);
/// `key`: the random stream for area lights' points.
Vec3f specular_radiance(const Scene& scene, const RayScene& rays, const PixelHit& hit, float eps,
                        std::uint64_t key);

class IrradianceCache;

/// The angular factor of multiple scattering when the scene asks for it (Scene::angular) and the
/// model takes it (materials::angular_factor_applies); else null.
inline std::unique_ptr<materials::AngularFactor> angular_factor_for(const Scene& scene,
                                                                    DiffusionModel model) {
  if (!scene.angular || !materials::angular_factor_applies(model)) return nullptr;
  return std::make_unique<materials::AngularFactor>(scene.material);
}

/// `cache`: area lights' irradiance from it (else shadow rays per hit); may be null.
/// `angular`: the incidence side's angular factor at each hit (may be null).
void probe_pass(const Scene& scene, DiffusionModel model, const ReferenceOptions& options,
                const RayScene& rays, const IrradianceCache* cache,
                const materials::AngularFactor* angular, const std::vector<PixelHit>& hits,
                const std::vector<std::uint32_t>& object_pixels, int pass, int threads,
                std::vector<std::array<double, 3>>& accumulated, std::uint64_t& probe_hits,
                const std::function<void(std::size_t)>& on_progress);

// Surface samples.

struct SurfaceSampler {
  explicit SurfaceSampler(const Mesh& mesh) : mesh_(mesh) {
    cdf_.resize(mesh.triangles.size() + 1, 0.0);
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto& tri = mesh.triangles[t];
      const Vec3d a = mesh.positions[tri[0]].cast<double>(),
                  b = mesh.positions[tri[1]].cast<double>(),
                  c = mesh.positions[tri[2]].cast<double>();
      cdf_[t + 1] = cdf_[t] + 0.5 * (b - a).cross(c - a).norm();
    }
  }
  double area() const { return cdf_.back(); }

  /// Sample k of n: stratum k of the area CDF (jittered by xi1), uniform within its triangle.
  void sample(std::size_t k, std::size_t n, double xi1, double xi2, Vec3f& x, Vec3f& normal,
              Vec3f& geometric_normal) const {
    const double target = (double(k) + xi1) / double(n) * area();
    auto it = std::upper_bound(cdf_.begin() + 1, cdf_.end() - 1, target);
    std::size_t t = std::size_t(it - cdf_.begin()) - 1;
    while (t > 0 && !(cdf_[t + 1] > cdf_[t])) --t;
    const double width = cdf_[t + 1] - cdf_[t];
    const double s = std::sqrt(width > 0 ? std::clamp((target - cdf_[t]) / width, 0.0, 1.0) : 0.5);
    const double b1 = s * (1 - xi2), b2 = s * xi2, b0 = 1 - b1 - b2;
    const auto& tri = mesh_.triangles[t];
    const Vec3f &p0 = mesh_.positions[tri[0]], &p1 = mesh_.positions[tri[1]],
                &p2 = mesh_.positions[tri[2]];
    x = (b0 * p0.cast<double>() + b1 * p1.cast<double>() + b2 * p2.cast<double>()).cast<float>();
    normal = (float(b0) * mesh_.normals[tri[0]] + float(b1) * mesh_.normals[tri[1]] +
              float(b2) * mesh_.normals[tri[2]])
                 .normalized();
    geometric_normal = (p1 - p0).cross(p2 - p0).normalized();
  }

 private:
  const Mesh& mesh_;
  std::vector<double> cdf_;
};

}  // namespace lucent::render::detail
