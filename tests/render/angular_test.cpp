// The angular factor of multiple scattering (materials/angular.h) held to what is true without it:
// Chandrasekhar's H-function against its published values, and the reference's multiple scattering
// on a wide slab lit and seen obliquely against the path tracer's (its image less the closed-form
// single scattering, slab_scene.h), which no diffusion model enters.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "lucent/materials/angular.h"
#include "lucent/render/path_tracer.h"
#include "lucent/render/reference_renderer.h"
#include "slab_scene.h"

namespace lucent::render {
namespace {

// Chandrasekhar (1960), Table XI, and tests/acquire/photon_transport_test: H(1) and H(0.5) at
// albedo 0.9; the conservative case's H(1) = 2.90781.
TEST(HFunction, MatchesItsPublishedValues) {
  const materials::HFunction h09(0.9), h1(1.0), h0(0.0);
  EXPECT_NEAR(h09(1.0), 1.85009852, 2e-7);
  EXPECT_NEAR(h09(0.5), 1.55603380, 2e-7);
  EXPECT_NEAR(h1(1.0), 2.90781, 2e-4);  // slowest convergence: omega = 1
  EXPECT_DOUBLE_EQ(h0(0.7), 1.0);
}

TEST(AngularFactor, IsOneAlongTheNormalAndReciprocal) {
  const materials::Material potato = materials::load_material("potato");
  const materials::AngularFactor k(potato);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(k(c, 1.0), 1.0, 1e-12);
    EXPECT_NEAR(k.two_sided(c, 0.3, 0.8), k.two_sided(c, 0.8, 0.3), 1e-12);
    // The separable factor is exact where incidence and exit make the same angle.
    for (const double mu : {0.25, 0.5, 0.75}) {
      EXPECT_NEAR(k(c, mu) * k(c, mu), k.two_sided(c, mu, mu), 2e-3 * k.two_sided(c, mu, mu))
          << c << " " << mu;  // the nodes' linear interpolation
    }
  }
}

Eigen::Vector3d at_angle(double deg, double azimuth_deg) {
  const double a = deg * std::numbers::pi / 180, b = azimuth_deg * std::numbers::pi / 180;
  return {std::sin(a) * std::cos(b), std::cos(a), std::sin(a) * std::sin(b)};
}

// The slab (slab_scene.h) lit at 60 degrees and seen at 60 degrees on the other side, eta 1: the
// tabulated reference's multiple scattering over the truth's. Without the factor it was 0.72-1.13
// (measured, printed); with it within 4% (the path tracer's noise at 1024 paths is 0.9%; the factor
// is exact for isotropic scattering at eta 1, and both materials scatter isotropically).
TEST(AngularFactor, ReferenceMatchesThePathTracersMultipleScatteringAt60Degrees) {
  for (const char* material : {"potato", "skin1"}) {
    testing_slab::SlabScene slab = testing_slab::make_slab_scene(material, 4);
    slab.scene.material.ior = 1.0;
    const Eigen::Vector3d w_i = at_angle(60, 0), w_o = at_angle(60, 180);
    slab.scene.lights[0].direction = w_i.cast<float>();
    slab.scene.camera.eye = Vec3f(0, 25, 0) + 300.0f * w_o.cast<float>();
    slab.scene.camera.fov_y_deg = 0.5;
    PathTraceOptions po;
    po.pixel_samples = 1024;
    po.threads = 2;
    const PathTraceImage truth = render_pathtrace(slab.scene, po);
    ReferenceOptions ro;
    ro.pixel_samples = 256;
    ro.threads = 2;
    double worst_without = 0;
    for (const bool angular : {false, true}) {
      slab.scene.angular = angular;
      const ReferenceImage ref = render_reference(slab.scene, DiffusionModel::kTabulated, ro);
      for (int c = 0; c < 3; ++c) {
        const double ms = truth.object_mean[std::size_t(c)] -
                          testing_slab::single_scattering_truth(slab.scene.material, c, w_i, w_o);
        const double ratio = testing_slab::centre_mean(ref.image, c) / ms;
        std::printf(
            "%s angular %s channel %d: reference / truth's multiple scattering %.3f (+-%.3f)\n",
            material, angular ? "on" : "off", c, ratio,
            truth.object_mean_error[std::size_t(c)] / ms);
        if (angular) {
          EXPECT_NEAR(ratio, 1.0, 0.04) << material << " channel " << c;
        } else {
          worst_without = std::max(worst_without, std::abs(ratio - 1));
        }
      }
    }
    EXPECT_GT(worst_without, 0.1) << material;  // the test sees what the factor fixes
  }
}

}  // namespace
}  // namespace lucent::render
