// The hierarchical boundary-element technique's CPU side: the face-cluster hierarchy, the links
// of the three modes, and B against the all-pairs solution.
#include "lucent/render/hierarchical.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "area_light.h"
#include "lucent/core/error.h"
#include "lucent/materials/dipole.h"
#include "lucent/materials/material.h"

namespace lucent::render::hierarchical {
namespace {

Scene sphere_scene(int level, const std::string& material, double size_mm = 100) {
  Scene scene;
  scene.mesh = load_mesh("sphere:" + std::to_string(level), size_mm);
  scene.material = materials::load_material(material);
  Light key;
  key.direction = Vec3f(1, 0.5, 0.3).normalized();
  key.radiance = {1, 1, 1};
  Light point;
  point.type = LightType::kPoint;
  point.position = {-60, 60, 80};
  point.radiance = {1e4, 1e4, 1e4};
  scene.lights = {key, point};
  return scene;
}

// Relative RMS of per-face B against a reference, over faces and channels.
double relative_rms(const std::vector<std::array<double, 3>>& b,
                    const std::vector<std::array<double, 3>>& ref) {
  double num = 0, den = 0;
  for (std::size_t t = 0; t < ref.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      const double d = b[t][std::size_t(c)] - ref[t][std::size_t(c)];
      num += d * d;
      den += ref[t][std::size_t(c)] * ref[t][std::size_t(c)];
    }
  return std::sqrt(num / den);
}

TEST(HierarchicalClusters, NestedRangesBoundariesAndGeometry) {
  const Mesh mesh = load_mesh("sphere:3", 100);
  const Hierarchy h = Hierarchy::build(mesh);
  const int T = int(mesh.triangles.size());
  ASSERT_EQ(int(h.clusters().size()), 2 * T - 1);  // a binary tree
  const Cluster& root = h[h.root()];
  EXPECT_EQ(root.first_face, 0);
  EXPECT_EQ(root.face_count, T);
  EXPECT_EQ(root.edge_count, 0);  // a closed mesh: every edge cancels
  EXPECT_LT(root.planarity(), 1e-6);  // a closed surface projects to nothing
  std::vector<int> seen(std::size_t(T), 0);
  for (int f : h.faces()) ++seen[std::size_t(f)];
  for (int s : seen) EXPECT_EQ(s, 1);
  double leaf_area = 0;
  for (std::size_t id = 0; id < h.clusters().size(); ++id) {
    const Cluster& c = h.clusters()[id];
    if (c.leaf()) {
      EXPECT_EQ(c.face_count, 1);
      EXPECT_EQ(c.edge_count, 3);
      EXPECT_NEAR(c.planarity(), 1.0, 1e-12);
      leaf_area += c.area;
      continue;
    }
    const Cluster& a = h[c.child[0]];
    const Cluster& b = h[c.child[1]];
    EXPECT_EQ(a.first_face, c.first_face);  // children partition the parent's range
    EXPECT_EQ(b.first_face, a.first_face + a.face_count);
    EXPECT_EQ(c.face_count, a.face_count + b.face_count);
    EXPECT_NEAR(c.area, a.area + b.area, 1e-9 * c.area);
    EXPECT_LE(c.edge_count, a.edge_count + b.edge_count);
    EXPECT_GE(c.radius + 1e-9, (a.midpoint - c.midpoint).norm() + a.radius);
  }
  EXPECT_NEAR(root.area, leaf_area, 1e-9 * leaf_area);
  // Compact clusters: balanced to within a factor of the ideal log2 depth.
  EXPECT_LE(h.depth(), 2 * int(std::ceil(std::log2(double(T)))));
}

// Per-face B against every triangle as an emitter through the exact form factor: the error falls
// as the oracle's thresholds tighten.
TEST(HierarchicalSolver, ApproachesTheAllPairsSolutionAsEpsilonTightens) {
  Scene scene = sphere_scene(2, "potato", 40);  // 320 triangles, 40 mm
  Options loose;
  loose.epsilon_1 = 0.2;
  loose.epsilon_2 = 1.0;
  loose.near = 0.2;
  Options mid;  // the defaults
  Options tight;
  tight.epsilon_1 = tight.epsilon_2 = 0.005;
  tight.near = 0.002;
  std::vector<double> errors;
  std::vector<long> link_counts;
  std::vector<std::array<double, 3>> reference;
  for (const Options& o : {loose, mid, tight}) {
    Solver solver(scene, o);
    solver.solve();
    if (reference.empty()) reference = all_pairs_B(scene.mesh, scene.material, solver.face_E(), o.form_factor);
    errors.push_back(relative_rms(solver.face_B(), reference));
    link_counts.push_back(solver.stats().links);
    std::printf("epsilon %.3g/%.3g near %.3g: %ld links (all pairs %zu), B relative RMS %.4f\n",
                o.epsilon_1, o.epsilon_2, o.near, solver.stats().links,
                scene.mesh.triangles.size() * scene.mesh.triangles.size(), errors.back());
  }
  EXPECT_GT(errors[0], errors[1]);
  EXPECT_GT(errors[1], errors[2]);
  EXPECT_LT(errors[1], 0.02);  // the defaults
  EXPECT_LT(errors[2], 0.005);
  EXPECT_LT(link_counts[0], link_counts[1]);
  EXPECT_LE(link_counts[2], long(scene.mesh.triangles.size() * scene.mesh.triangles.size()));
}

TEST(HierarchicalSolver, RenderModeEqualsOnTheFly) {
  Scene scene = sphere_scene(3, "marble");
  Options render, fly;
  fly.mode = Mode::kOnTheFly;
  Solver a(scene, render), b(scene, fly);
  a.solve();
  a.solve();  // a second frame reuses the links
  b.solve();
  double worst = 0;
  for (std::size_t v = 0; v < a.vertex_B().size(); ++v)
    for (int c = 0; c < 3; ++c) {
      const double x = a.vertex_B()[v][std::size_t(c)], y = b.vertex_B()[v][std::size_t(c)];
      worst = std::max(worst, std::abs(x - y) / std::max(std::abs(y), 1e-300));
    }
  EXPECT_LT(worst, 1e-12);
  EXPECT_EQ(a.stats().links, b.stats().links);
  EXPECT_EQ(a.stats().form_factor_calls, 0);  // render mode: no form factor in a lit frame
  EXPECT_GT(b.stats().form_factor_calls, 0);
}

// The oracle's subproblems are linked on threads: the links, their order and so B are the same
// to the last bit for any number, in each mode.
TEST(HierarchicalSolver, TheSameLinksAndBOnAnyNumberOfThreads) {
  Scene scene = sphere_scene(3, "marble");
  scene.geometry_factor = true;
  for (const Mode mode : {Mode::kRender, Mode::kOnTheFly}) {
    Options one, three;
    one.mode = three.mode = mode;
    one.threads = 1;
    three.threads = 3;
    Solver a(scene, one), b(scene, three);
    a.solve();
    b.solve();
    EXPECT_EQ(a.stats().links, b.stats().links);
    EXPECT_EQ(a.stats().edge_segments, b.stats().edge_segments);
    EXPECT_EQ(a.stats().point_samples, b.stats().point_samples);
    for (std::size_t t = 0; t < a.face_B().size(); ++t)
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(a.face_B()[t][std::size_t(c)], b.face_B()[t][std::size_t(c)]);
    EXPECT_GT(a.stats().memory_mib, 0);
  }
  Options bad;
  bad.threads = -1;
  try {
    Solver(scene, bad);
    ADD_FAILURE() << "threads -1 accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--hierarchical-threads"), std::string::npos) << e.what();
  }
}

// A deformation, then incremental frames (a small budget) until they agree with a from-scratch
// solve of the deformed mesh; a material change likewise.
TEST(HierarchicalSolver, IncrementalConvergesToOnTheFly) {
  Scene scene = sphere_scene(3, "potato");
  Options inc;
  inc.mode = Mode::kIncremental;
  inc.budget = 20000;  // of ~150,000 links: the repair takes several frames
  Solver solver(scene, inc);
  solver.solve();
  std::vector<Vec3f> moved = scene.mesh.positions;
  for (Vec3f& p : moved) p.x() *= 0.7f;  // squash
  Mesh deformed = scene.mesh;
  deformed.positions = moved;
  deformed.normals = area_weighted_normals(deformed);
  solver.set_geometry(deformed.positions, deformed.normals);
  materials::Material m = materials::load_material("marble");
  solver.set_material(m);

  Scene target = scene;
  target.mesh = deformed;
  target.material = m;
  Options fly;
  fly.mode = Mode::kOnTheFly;
  Solver truth(target, fly);
  truth.solve();
  std::vector<double> errors;
  for (int frame = 0; frame < 60; ++frame) {
    solver.solve();
    errors.push_back(relative_rms(solver.face_B(), truth.face_B()));
    if (solver.stats().demoted + solver.stats().promoted + solver.stats().refreshed == 0) break;
  }
  std::printf("incremental: %zu frames, error first %.4f last %.2e\n", errors.size(),
              errors.front(), errors.back());
  EXPECT_GT(errors.size(), 2u);  // the budget spreads the repair over frames
  EXPECT_GT(errors.front(), 10 * errors.back());
  EXPECT_LT(errors.back(), 0.01);
}

// A large flat tessellated plane lit uniformly: B / E at the centre is the dipole's R_tot.
TEST(HierarchicalSolver, FlatPlaneGivesTheTotalDiffuseReflectance) {
  Scene scene;
  scene.material = materials::load_material("marble");
  const int n = 40;
  const double half = 150;  // mm; marble's 1 / sigma_tr is 3-9 mm
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      scene.mesh.positions.push_back(Vec3f(float(-half + 2 * half * i / n), 0.0f,
                                           float(-half + 2 * half * j / n)));
      scene.mesh.normals.push_back(Vec3f(0, 1, 0));
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const unsigned a = unsigned(j * (n + 1) + i), b = a + 1, c = a + unsigned(n + 1), d = c + 1;
      scene.mesh.triangles.push_back({a, c, b});
      scene.mesh.triangles.push_back({b, c, d});
    }
  Light sun;
  sun.direction = {0, 1, 0};
  scene.lights = {sun};
  Options o;
  o.shadows = false;
  Solver solver(scene, o);
  solver.solve();
  // The two triangles at the centre.
  const int centre = 2 * ((n / 2) * n + n / 2);
  for (int c = 0; c < 3; ++c) {
    const auto coeff = materials::derive_coefficients(scene.material.medium(c));
    const double R_tot = materials::dipole_total_reflectance(coeff.alpha_prime, coeff.A_dipole);
    const double ratio = solver.face_B()[std::size_t(centre)][std::size_t(c)] /
                         solver.face_E()[std::size_t(centre)][std::size_t(c)];
    EXPECT_NEAR(ratio / R_tot, 1.0, 0.02) << "channel " << c;
  }
}

// Link counts against the seed's Table 3 (marble, 2.5 cm, T 2016 -> L 89K ... 131736 -> 6905K,
// L ~ T^1.045): our oracle on icospheres of the same scale; the exponent is fitted and reported.
TEST(HierarchicalSolver, LinkCountGrowsNearLinearly) {
  std::vector<double> logT, logL;
  for (int level = 2; level <= 4; ++level) {
    Scene scene = sphere_scene(level, "marble", 25);
    Solver solver(scene, Options{});
    solver.solve();
    logT.push_back(std::log(double(scene.mesh.triangles.size())));
    logL.push_back(std::log(double(solver.stats().links)));
    std::printf("T %zu: L %ld (L/T %.1f), %s\n", scene.mesh.triangles.size(), solver.stats().links,
                double(solver.stats().links) / double(scene.mesh.triangles.size()),
                solver.stats().to_string().c_str());
  }
  const double slope = (logL.back() - logL.front()) / (logT.back() - logT.front());
  std::printf("link count exponent %.3f (seed's Table 3: 1.045)\n", slope);
  EXPECT_GT(slope, 0.9);
  EXPECT_LT(slope, 1.4);  // far from the all-pairs exponent 2
}

TEST(HierarchicalSolver, BadOptionsAreRefused) {
  Scene scene = sphere_scene(1, "marble");
  Options o;
  o.epsilon_1 = 0;
  EXPECT_THROW(Solver(scene, o), lucent::Error);
  o = {};
  o.form_factor.edge_constant = -1;
  EXPECT_THROW(Solver(scene, o), lucent::Error);
  EXPECT_THROW(parse_mode("sometimes"), lucent::Error);
}

// Area lights: the leaves' irradiance from the projection-map cache against 16 shadow rays per
// leaf (both with the analytic form factor as control variate): the cache changes B by well
// under a percent.
TEST(HierarchicalSolver, AreaLightIrradianceCacheAgreesWithShadowRays) {
  Scene scene = sphere_scene(3, "marble", 100);
  const Vec3f c(50, 50, 40);
  const Vec3f n = -c.normalized();
  const Vec3f u = 25.0f * Vec3f(n.unitOrthogonal()), v = 25.0f * Vec3f(n.cross(u).normalized());
  scene.lights = {rect_light(c, u, v, Vec3f(1, 1, 1))};
  Options cached, rays;
  rays.irradiance_cache = false;
  Solver a(scene, cached), b(scene, rays);
  a.solve();
  b.solve();
  double lit = 0;
  for (const auto& e : a.face_E()) lit += e[0] > 0 ? 1 : 0;
  EXPECT_GT(lit, 0.3 * double(a.face_E().size()));  // the lit side
  const double e = relative_rms(a.face_E(), b.face_E()), bb = relative_rms(a.face_B(), b.face_B());
  std::printf("hierarchical area light: cache vs shadow rays: E %.3f%%, B %.3f%% relative RMS\n",
              100 * e, 100 * bb);
  EXPECT_LT(e, 0.01);
  EXPECT_LT(bb, 0.005);
  // A second solve reuses the cache (nothing changed): the same irradiance.
  a.solve();
  EXPECT_LT(relative_rms(a.face_E(), b.face_E()), e + 1e-12);
}

}  // namespace
}  // namespace lucent::render::hierarchical
