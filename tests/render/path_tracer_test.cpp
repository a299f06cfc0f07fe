// `--technique pathtrace` held to what is true without it: the white furnace (a non-absorbing
// object under a uniform sky is invisible), Chandrasekhar's semi-infinite medium (the H-function's
// reflection function), the slab simulator (lucent simulate's Monte Carlo, written separately from
// MCML's scheme) through a refracting boundary, and the connection through a curved boundary
// against the exact ray tube of a true sphere.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <numbers>

#include "lucent/acquire/photon_transport.h"
#include "lucent/imaging/image_io.h"
#include "lucent/render/path_tracer.h"
#include "lucent/render/reference_renderer.h"
#include "lucent/render/scene.h"
#include "path_walk.h"
#include "slab_scene.h"

namespace lucent::render {
namespace {

constexpr double kPi = std::numbers::pi;
using pathtrace::Vec3d;
// Chandrasekhar's H-function, isotropic scattering, albedo 0.9 (tests/acquire/photon_transport_test
// derives them: Simpson's rule on the integral form, converged to the digits shown).
constexpr double kH1Albedo09 = 1.85009852;   // H(1)
constexpr double kH05Albedo09 = 1.55603380;  // H(0.5)

materials::Material grey(double sigma_a, double sigma_s, double g, double eta) {
  materials::Material m;
  m.name = "grey";
  m.ior = eta;
  m.sigma_a = {sigma_a, sigma_a, sigma_a};
  m.sigma_s = materials::Rgb{sigma_s, sigma_s, sigma_s};
  m.g = materials::Rgb{g, g, g};
  m.sigma_s_reduced = {sigma_s * (1 - g), sigma_s * (1 - g), sigma_s * (1 - g)};
  return m;
}

// The wide box of slab_scene.h, seen at `view_deg` from its normal (in the x-y plane), lit along
// its normal; the camera's field spans a few mm of the face's centre.
Scene slab(const materials::Material& material, double view_deg, int pixels) {
  testing_slab::SlabScene s = testing_slab::make_slab_scene("marble", pixels);
  s.scene.material = material;
  const double a = view_deg * kPi / 180;
  Camera& camera = s.scene.camera;
  camera.eye = Vec3f(float(300 * std::sin(a)), float(25 + 300 * std::cos(a)), 0);
  camera.up = Vec3f(0, 0, -1);
  camera.fov_y_deg = 1;
  return s.scene;
}

double channel_mean(const PathTraceImage& r) {
  return (r.object_mean[0] + r.object_mean[1] + r.object_mean[2]) / 3;
}
double channel_error(const PathTraceImage& r) {  // one path carries all three: correlated
  const auto& e = r.object_mean_error;
  return (e[0] + e[1] + e[2]) / 3;
}

TEST(PathTracer, WhiteFurnaceSphereIsInvisible) {
  // A sphere that absorbs nothing under a sky of radiance 1: whatever enters leaves, so every
  // pixel sees 1. Through a refracting boundary every path returns exactly 1 (no estimate is
  // weighted: the sky is reached only by escaping); with eta = 1 the sky is also sampled at every
  // collision (MIS), so each pixel is 1 within its noise.
  const auto dir = std::filesystem::temp_directory_path() / "lucent_path_tracer_furnace";
  std::filesystem::create_directories(dir);
  const auto sky = dir / "white.exr";
  imaging::write_exr(sky, ImageRgb(16, 8, 1.0f));
  for (const double eta : {1.5, 1.0}) {
    Scene scene;
    scene.mesh = load_mesh("sphere:2", 30);
    scene.material = grey(0, 1.5, 0.6, eta);
    scene.environment = sky;
    scene.specular = true;
    scene.camera = orbit_camera(scene.mesh, 0, 0, 3, 16, 16);
    PathTraceOptions o;
    o.pixel_samples = eta == 1.0 ? 256 : 4;
    o.threads = 2;
    const PathTraceImage r = render_pathtrace(scene, o);
    double worst = 0;
    for (std::size_t p = 0; p < r.mask.size(); ++p) {
      for (std::size_t c = 0; c < 3; ++c) {
        const double v = r.image.data[3 * p + c];
        const double se = r.standard_error.data[3 * p + c];
        if (eta != 1.0) {
          EXPECT_NEAR(v, 1.0, 1e-6) << "pixel " << p;
        } else {
          EXPECT_NEAR(v, 1.0, 5 * se + 1e-6) << "pixel " << p;
        }
        worst = std::max(worst, std::abs(v - 1));
      }
    }
    EXPECT_EQ(r.stats.details["leaked_paths"].get<std::uint64_t>(), 0u);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(r.object_mean[std::size_t(c)], 1.0,
                  4 * r.object_mean_error[std::size_t(c)] + 1e-6);
    std::cout << "[ measured ] furnace eta " << eta << ": worst pixel |L - 1| = " << worst
              << ", object mean " << channel_mean(r) << " +- " << channel_error(r) << "\n";
  }
}

TEST(PathTracer, SemiInfiniteMediumGivesChandrasekharsReflection) {
  // eta = 1, isotropic, albedo 0.9, lit along the normal (mu_0 = 1), seen at mu:
  // L = E omega / (4 pi) mu_0 / (mu + mu_0) H(mu) H(mu_0).
  for (const double view_deg : {0.0, 60.0}) {
    const Scene scene = slab(grey(1.0, 9.0, 0.0, 1.0), view_deg, 8);
    PathTraceOptions o;
    o.pixel_samples = 256;
    o.threads = 2;
    const PathTraceImage r = render_pathtrace(scene, o);
    const double mu = std::cos(view_deg * kPi / 180);
    const double H_mu = view_deg == 0 ? kH1Albedo09 : kH05Albedo09;
    const double expected = 0.9 / (4 * kPi) * H_mu * kH1Albedo09 / (mu + 1);
    const double mean = channel_mean(r), se = channel_error(r);
    EXPECT_NEAR(mean, expected, 4 * se) << "view " << view_deg;
    EXPECT_LT(se, 0.01 * expected);
    std::cout << "[ measured ] Chandrasekhar, view " << view_deg << " deg: L = " << mean << " +- "
              << se << " (H-function " << expected << ", ratio " << mean / expected << ")\n";
  }
}

TEST(PathTracer, RefractingSlabMatchesTheSlabSimulator) {
  // eta 1.4, forward scattering: the light reaches every collision through the refracting face
  // (the connection), the camera sees through it. The simulator's next-event image integrates
  // to the radiance of the face under a uniform beam of unit irradiance.
  const materials::Medium<double> medium{0.05, 4.0, 0.7, 1.4};
  for (const double view_deg : {0.0, 40.0}) {
    acquire::PhotonTransportOptions sim;
    sim.media = {medium, medium, medium};
    sim.channels = {true, false, false};
    sim.photons = 400'000;
    sim.image = true;
    sim.size = 256;
    sim.pixel_mm = 0.25;  // +-32 mm: about 15 diffusion lengths
    sim.view_deg = view_deg;
    sim.threads = 2;
    const auto truth = acquire::simulate_photon_transport(sim).channels[0].image_integral;

    const Scene scene =
        slab(grey(medium.sigma_a, medium.sigma_s, medium.g, medium.eta), view_deg, 8);
    PathTraceOptions o;
    o.pixel_samples = 384;
    o.threads = 2;
    const PathTraceImage r = render_pathtrace(scene, o);
    const double mean = channel_mean(r), se = channel_error(r);
    const double both = std::hypot(se, truth.standard_error);
    EXPECT_NEAR(mean, truth.value, 4 * both) << "view " << view_deg;
    EXPECT_LT(both, 0.02 * truth.value);
    EXPECT_EQ(r.stats.details["connection_failures"].get<std::uint64_t>(), 0u);
    std::cout << "[ measured ] slab eta 1.4 g 0.7, view " << view_deg << " deg: path tracer "
              << mean << " +- " << se << ", simulator " << truth.value << " +- "
              << truth.standard_error << " (ratio " << mean / truth.value << ")\n";
  }
}

// The refracted connection's beam on a sphere: the irradiance perpendicular to the refracted sun
// beam at a point inside, from the exact ray tube of a true sphere (analytic entry points and
// normals, the tube's cross-section by central differences of the incoming rays' offsets) against
// the connection on an icosphere of 20480 faces with interpolated normals.
double sphere_beam_irradiance(const Vec3d& x, const Vec3d& to_light, double radius, double eta,
                              Vec3d& travel) {
  using pathtrace::refract;
  const Vec3d a = to_light.unitOrthogonal(), b = to_light.cross(a);
  // The incoming ray at perpendicular offset (u, v): its entry point, normal and refracted travel.
  const auto ray = [&](double u, double v, Vec3d& entry, Vec3d& t) {
    const Vec3d p = u * a + v * b;  // its closest approach to the centre
    const double h2 = radius * radius - p.squaredNorm();
    entry = p + std::sqrt(h2) * to_light;
    return refract(-to_light, entry / radius, eta, t);
  };
  // Which ray passes through x: fixed point on the true sphere.
  Vec3d entry, t;
  double u = x.dot(a), v = x.dot(b);
  for (int k = 0; k < 200; ++k) {
    ray(u, v, entry, t);
    const Vec3d miss = x - entry - (x - entry).dot(t) * t;  // x's offset from the refracted ray
    u += miss.dot(a), v += miss.dot(b);
    if (miss.norm() < 1e-12) break;
  }
  ray(u, v, entry, travel);
  const double h = 1e-4;
  std::array<Vec3d, 4> q;
  const std::array<std::array<double, 2>, 4> steps{{{h, 0}, {-h, 0}, {0, h}, {0, -h}}};
  for (std::size_t k = 0; k < 4; ++k) {
    Vec3d e, tk;
    ray(u + steps[k][0], v + steps[k][1], e, tk);
    q[k] = e + ((x - e).dot(travel) / tk.dot(travel)) * tk;
  }
  const double area_after = std::abs((q[0] - q[1]).cross(q[2] - q[3]).dot(travel));
  const double cos_i = to_light.dot(entry / radius);
  return (1 - materials::fresnel_reflectance(cos_i, eta)) * (2 * h) * (2 * h) / area_after;
}

TEST(PathTracer, RefractedConnectionFollowsACurvedBoundarysBeam) {
  Scene scene;
  scene.mesh = load_mesh("sphere:5", 60);
  const Vec3f centre = scene.mesh.centre();
  for (Vec3f& p : scene.mesh.positions) p -= centre;
  const double radius = scene.mesh.bounding_radius();
  scene.material = grey(0.01, 1.0, 0.0, 1.4);
  const pathtrace::Boundary boundary(scene.mesh);
  const pathtrace::Lights lights = pathtrace::gather_lights(scene);
  const PathTraceOptions options;
  double eta = 1;
  pathtrace::World world{boundary, lights, pathtrace::medium_of(scene.material, eta), 1.4, false,
                         options,  false};
  Light sun;
  sun.direction = Vec3f(0.3f, 0.2f, 1.0f).normalized();
  const Vec3d to_light = sun.direction.cast<double>();
  double worst = 0;
  // Points at depths of 0.5 to 12 mm under lit places, from the sub-solar point to 60 degrees off.
  for (const double off_deg : {0.0, 30.0, 60.0}) {
    const Vec3d axis = to_light.unitOrthogonal();
    const Vec3d surface =
        radius * Eigen::AngleAxisd(off_deg * kPi / 180, axis).toRotationMatrix() * to_light;
    for (const double depth : {0.5, 3.0, 12.0}) {
      const Vec3d x = surface * (1 - depth / radius);
      pathtrace::Connection link;
      ASSERT_EQ(pathtrace::refracted_connection(world, sun, x, link), pathtrace::Link::kConnected)
          << off_deg << " deg, depth " << depth;
      Vec3d travel;
      const double truth = sphere_beam_irradiance(x, to_light, radius, 1.4, travel);
      // The icosphere's facets sit inside the sphere by up to their sagitta while its normals are
      // radial, which tilts the beam's cross-section at oblique incidence: measured 0.1% at 30
      // degrees and 0.56% at 60 on sphere:4, :5 and :6 alike (the same formulas on the true sphere
      // reproduce the ray tube to 1e-6: checked while writing this test).
      const double tolerance = off_deg < 45 ? 2e-3 : 1e-2;
      EXPECT_NEAR(link.irradiance, truth, tolerance * truth) << off_deg << " deg, depth " << depth;
      EXPECT_GT(link.travel.dot(travel), std::cos(2e-3)) << off_deg << " deg, depth " << depth;
      worst = std::max(worst, std::abs(link.irradiance / truth - 1));
    }
  }
  std::cout << "[ measured ] connection on sphere:5 against the true sphere's ray tube: worst "
               "relative irradiance error "
            << worst << "\n";
}

TEST(PathTracer, EveryLightTheSameThroughBothConnections) {
  // eta = 1 reaches the lights by straight next-event estimates with MIS; eta = 1 + 1e-6 (the
  // same light to 1e-12) takes the other road: delta and area lights through the refracted
  // connection, area-light hits only after an internal event, the sky only by escaping. A sun,
  // a point light, a rect light and a sky on a sphere: the two must agree within their noise.
  const auto dir = std::filesystem::temp_directory_path() / "lucent_path_tracer_roads";
  std::filesystem::create_directories(dir);
  const auto sky = dir / "sky.exr";
  ImageRgb sky_image(16, 8, 0.0f);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x)
      for (int c = 0; c < 3; ++c) sky_image.at(x, y, c) = float(0.2 + 0.1 * c + (y < 3 ? 0.5 : 0));
  imaging::write_exr(sky, sky_image);
  std::array<std::array<double, 3>, 2> mean{}, error{};
  for (int road = 0; road < 2; ++road) {
    Scene scene;
    scene.mesh = load_mesh("sphere:3", 20);
    scene.material = grey(0.05, 1.0, 0.5, road == 0 ? 1.0 : 1.0 + 1e-6);
    scene.material.sigma_a = {0.02, 0.05, 0.2};
    scene.lights = {parse_light("directional:0.4,0.8,0.6:0.6,0.6,0.6"),
                    parse_light("point:-30,10,40:300,300,300"),
                    parse_light("rect:20,-5,30:0,4,0:3,0,-2:40,40,40")};
    scene.environment = sky;
    scene.specular = false;
    scene.camera = orbit_camera(scene.mesh, 20, 10, 3, 12, 12);
    PathTraceOptions o;
    o.pixel_samples = 96;
    o.threads = 2;
    o.seed = 11 + std::uint64_t(road);
    const PathTraceImage r = render_pathtrace(scene, o);
    mean[std::size_t(road)] = r.object_mean;
    error[std::size_t(road)] = r.object_mean_error;
    EXPECT_EQ(r.stats.details["connection_failures"].get<std::uint64_t>(), 0u);
  }
  for (std::size_t c = 0; c < 3; ++c) {
    const double both = std::hypot(error[0][c], error[1][c]);
    EXPECT_NEAR(mean[1][c], mean[0][c], 4 * both) << "channel " << c;
    EXPECT_LT(both, 0.03 * mean[0][c]) << "channel " << c;
    std::cout << "[ measured ] channel " << c << ": straight " << mean[0][c] << " +- "
              << error[0][c] << ", through the boundary " << mean[1][c] << " +- " << error[1][c]
              << " (ratio " << mean[1][c] / mean[0][c] << ")\n";
  }
}

// The reference with its single-scattering term against the path tracer on the slab lit and seen
// along the normal, where the tabulated model is exact for multiple scattering: the sum is the
// truth (measured 1.002-1.010 for potato, skin1 and marble at eta 1 and 1.3, path-tracer noise
// 0.5-0.7%), and the multiple scattering alone misses 7-49% of it.
TEST(PathTracer, ReferenceWithSingleScatteringIsTheTruthOnTheSlab) {
  for (const auto& [name, eta] : std::vector<std::pair<std::string, double>>{
           {"skin1", 1.0}, {"skin1", 1.3}, {"marble", 1.3}}) {
    materials::Material m = materials::load_material(name);
    m.ior = eta;
    Scene scene = slab(m, 0.0, 8);
    PathTraceOptions o;
    o.pixel_samples = 256;
    o.threads = 2;
    const PathTraceImage truth = render_pathtrace(scene, o);
    ReferenceOptions ro;
    ro.threads = 2;
    ro.pixel_samples = 256;
    ro.single_samples = 64;
    scene.single_scattering = true;
    const ReferenceImage both = render_reference(scene, materials::DiffusionModel::kTabulated, ro);
    scene.single_scattering = false;
    const ReferenceImage ms = render_reference(scene, materials::DiffusionModel::kTabulated, ro);
    for (int c = 0; c < 3; ++c) {
      const double t = truth.object_mean[std::size_t(c)];
      const double se = truth.object_mean_error[std::size_t(c)] / t;
      const double with = testing_slab::centre_mean(both.image, c) / t;
      const double without = testing_slab::centre_mean(ms.image, c) / t;
      // The table's own accuracy (0.6-0.8%) beside four of the path tracer's standard errors.
      EXPECT_NEAR(with, 1.0, 0.008 + 4 * se) << name << " eta " << eta << " channel " << c;
      EXPECT_LT(without, 0.95) << name << " eta " << eta << " channel " << c;
      std::cout << "[ measured ] slab " << name << " eta " << eta << " channel " << c
                << ": (multiple + single) / truth " << with << ", multiple alone " << without
                << " (truth +- " << se << ")\n";
    }
  }
}

}  // namespace
}  // namespace lucent::render
