// The single-scattering term of the real-time techniques (render/core/single_scattering.h and its
// GLSL twin) held to what is true without it: the closed form of a semi-infinite medium under a
// plane boundary (the integral along the refracted view ray of a collimated refracted beam,
// Hanrahan and Krueger 1993's first order) and the path tracer's Monte Carlo single scattering
// through the exact refracted connection on a wide box. The GLSL twin is held to the same closed
// form through the radiance maps' image of that box (slab_truth_test.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <utility>

#include "lucent/materials/fresnel.h"
#include "path_walk.h"
#include "single_scattering.h"
#include "slab_scene.h"

namespace lucent::render {
namespace {

using Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;

materials::Material medium(double sigma_a, double sigma_s, double g, double eta) {
  materials::Material m;
  m.name = "single";
  m.ior = eta;
  m.sigma_a = {sigma_a, 2 * sigma_a, 4 * sigma_a};
  m.sigma_s = materials::Rgb{sigma_s, 0.7 * sigma_s, 0.4 * sigma_s};
  m.g = materials::Rgb{g, g, g};
  for (int c = 0; c < 3; ++c) m.sigma_s_reduced[c] = (*m.sigma_s)[c] * (1 - g);
  return m;
}

Vector3d at_angle(double deg, double azimuth_deg = 0) {  // unit, deg from +y, in the x-y plane
  const double a = deg * kPi / 180, b = azimuth_deg * kPi / 180;
  return {std::sin(a) * std::cos(b), std::cos(a), std::sin(a) * std::sin(b)};
}

Vector3d twin_on_plane(const detail::SingleMedium& m, const Vector3d& w_i, const Vector3d& w_o,
                       int steps) {
  const auto plane = [](const Vector3d& x, const Vector3d& w) {
    detail::LightEntry e;
    e.found = w.y() > 0;
    e.distance_mm = -x.y() / w.y();
    e.normal = Vector3d::UnitY();
    return e;
  };
  detail::SingleLight sun;
  sun.toward = w_i;
  return detail::single_scattering_radiance(m, Vector3d::Zero(), Vector3d::UnitY(), w_o, sun, steps,
                                            plane);
}

struct Angles {
  double light_deg, view_deg, azimuth_deg;
};

// Lit and seen along the normal (slab_scene.h: single_scattering_truth) the quadrature is exact
// (its integrand is linear in u); lit and seen at up to 60 degrees, 8 midpoints are within 0.5%
// (measured: the worst of these is printed).
TEST(SingleScattering, QuadratureMatchesTheClosedFormOfASemiInfiniteMedium) {
  double worst_normal = 0, worst_oblique = 0;
  for (const double eta : {1.0, 1.3, 1.5}) {
    for (const double g : {0.0, 0.5, 0.9}) {
      const materials::Material material = medium(0.02, 1.5, g, eta);
      const detail::SingleMedium m = detail::SingleMedium::of(material);
      for (const Angles a : {Angles{0, 0, 0}, Angles{60, 0, 0}, Angles{0, 60, 0},
                             Angles{60, 60, 180}, Angles{60, 60, 0}, Angles{45, 30, 90}}) {
        const Vector3d w_i = at_angle(a.light_deg), w_o = at_angle(a.view_deg, a.azimuth_deg);
        const Vector3d got = twin_on_plane(m, w_i, w_o, detail::kSingleScatteringSteps);
        for (int c = 0; c < 3; ++c) {
          const double truth = testing_slab::single_scattering_truth(material, c, w_i, w_o);
          ASSERT_GT(truth, 0);
          const double error = std::abs(got[c] / truth - 1);
          double& worst = a.light_deg == 0 && a.view_deg == 0 ? worst_normal : worst_oblique;
          worst = std::max(worst, error);
        }
      }
    }
  }
  std::printf("single scattering quadrature: normal %.2e, oblique %.2e of the closed form\n",
              worst_normal, worst_oblique);
  EXPECT_LT(worst_normal, 1e-12);
  EXPECT_LT(worst_oblique, 0.005);
  EXPECT_GT(worst_oblique, 0.0);  // not exact there: the test measures the quadrature
}

// Channels of close sigma_t (within 1.25: here 1.52, 1.48, 1.45 mm^-1, as potato's or marble's)
// share one set of points drawn for the smallest, each weighted by e^(-(sigma_t - sigma_ref) s);
// within 2 (1.52, 2.23, 2.95, as skin1's 0.77, 1.05, 1.49) they share 12: within 1% of the closed
// form lit and seen at up to 60 degrees (measured: printed; 8 shared points were 1.8% at 2.95).
TEST(SingleScattering, SharedPointsOfCloseChannelsMatchTheClosedForm) {
  double worst = 0;
  const materials::Rgb close{1.5, 1.45, 1.4}, wider{1.5, 2.2, 2.9};
  for (const auto& [eta, sigma_s] : {std::pair{1.0, close}, std::pair{1.3, close},
                                     std::pair{1.0, wider}, std::pair{1.3, wider}}) {
    materials::Material material = medium(0.02, 1.5, 0.5, eta);
    material.sigma_a = {0.02, 0.03, 0.05};
    material.sigma_s = sigma_s;
    const detail::SingleMedium m = detail::SingleMedium::of(material);
    for (const Angles a :
         {Angles{0, 0, 0}, Angles{60, 0, 0}, Angles{60, 60, 180}, Angles{45, 30, 90}}) {
      const Vector3d w_i = at_angle(a.light_deg), w_o = at_angle(a.view_deg, a.azimuth_deg);
      const Vector3d got = twin_on_plane(m, w_i, w_o, detail::kSingleScatteringSteps);
      for (int c = 0; c < 3; ++c) {
        const double truth = testing_slab::single_scattering_truth(material, c, w_i, w_o);
        worst = std::max(worst, std::abs(got[c] / truth - 1));
      }
    }
  }
  std::printf("shared points: worst %.2e of the closed form\n", worst);
  EXPECT_LT(worst, 0.01);
}

// The path tracer's single scattering (Monte Carlo along the refracted view ray, the exact
// refracted connection to the sun, written independently) at the centre of the wide box: the closed
// form within 3 standard errors.
TEST(SingleScattering, ClosedFormIsThePathTracersSingleScattering) {
  testing_slab::SlabScene slab = testing_slab::make_slab_scene("marble", 8);
  slab.scene.material = medium(0.02, 1.5, 0.5, 1.4);
  const Vector3d w_i = at_angle(50), w_o = at_angle(35, 140);
  slab.scene.lights[0].direction = w_i.cast<float>();
  const pathtrace::Boundary boundary(slab.scene.mesh);
  const pathtrace::Lights lights = pathtrace::gather_lights(slab.scene);
  const PathTraceOptions options;
  double eta = 1;
  const pathtrace::MediumRgb rgb = pathtrace::medium_of(slab.scene.material, eta);
  const pathtrace::World world{boundary, lights, rgb, eta, false, options, false};
  pathtrace::SurfacePoint p;
  p.x = Vector3d(0, 25, 0);
  p.n = p.ng = Vector3d::UnitY();
  pathtrace::WalkCounts counts;
  const int n = 200000;
  Vector3d sum = Vector3d::Zero(), sum2 = Vector3d::Zero();
  for (int k = 0; k < n; ++k) {
    pathtrace::Random random(detail::mix(0x5eedu + std::uint64_t(k)));
    const Vector3d v = pathtrace::single_scattering(world, p, w_o, random, counts);
    sum += v;
    sum2 += v.cwiseProduct(v);
  }
  const materials::Material& material = slab.scene.material;
  for (int c = 0; c < 3; ++c) {
    const double mean = sum[c] / n;
    const double error = std::sqrt(std::max(sum2[c] / n - mean * mean, 0.0) / n);
    const double truth = testing_slab::single_scattering_truth(material, c, w_i, w_o);
    std::printf("channel %d: path tracer %.6g +- %.2g, closed form %.6g (%+.2f%%)\n", c, mean,
                error, truth, 100 * (mean / truth - 1));
    EXPECT_NEAR(mean, truth, 3 * error + 1e-4 * truth) << "channel " << c;
  }
}

}  // namespace
}  // namespace lucent::render
