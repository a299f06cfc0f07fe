// The hierarchical boundary-element technique (`--technique hierarchical`, Mertens et al.: Mertens,
// Kautz, Bekaert, Seidel, Van Reeth 2003). B(x_o) = integral of E(x_i) R_d(x_i, x_o) dx_i is
// solved on a face-cluster hierarchy (hierarchical_clusters.h) in the manner of hierarchical
// radiosity:
//   links: from the root to itself, refined by a solid-angle oracle (below);
//   per frame: irradiance E at the leaves (the triangles' midpoints, shadow rays as the
//   reference's), pulled up as area-weighted averages; B gathered over the links
//   (B_R += F(E, R) E_E, F the form factor of hierarchical_form_factor.h or a single midpoint
//   sample); pushed down (each child adds its parent's B); per-vertex B (area-weighted over the
//   faces around a welded vertex) to the GPU, where the fragment shader takes (1 / pi) F_t(eta, n .
//   w_o) B.
//
// The oracle (the seed gives the rule, not the thresholds; lucent's "deviation" and defaults):
//   omega(x, E) = 2 pi (1 - d / sqrt(d^2 + A_E / pi)), the solid angle of a disc of E's area at
//   E's midpoint seen from x at distance d (bounded by 2 pi, so a receiver inside E is finite);
//   split the receiver R when max over R's children c of |omega(c, E) - omega(R, E)| > epsilon_1;
//   else split the emitter E when omega(R, E) > epsilon_2;
//   else split E when omega(R, E) > near and E is not planar (A' / A < min_planarity);
//   else link: the semi-analytic form factor when omega(R, E) > near (the "near" rule), a single
//   sample A_E R_d(R, E's midpoint) otherwise ("far").
// Leaves are never split (the seed's proof of concept does not subdivide faces either).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "lucent/render/hierarchical_clusters.h"
#include "lucent/render/hierarchical_form_factor.h"
#include "lucent/render/scene.h"

namespace lucent::render::hierarchical {

enum class Mode {
  kRender,       ///< links kept; a frame updates irradiance and gathers (lights move)
  kIncremental,  ///< links kept and repaired: a material change refreshes every link's factor, a
                 ///< geometry change re-checks links, demoting or promoting one level, within a
                 ///< per-frame budget of form-factor evaluations
  kOnTheFly,     ///< no stored links: the oracle is traversed and gathered from scratch each frame
};
Mode parse_mode(const std::string& text);  ///< render | incremental | on-the-fly
std::string to_string(Mode mode);

struct Options {
  // Defaults from a sweep on a 100 mm icosphere of 1280 triangles under two lights (potato,
  // marble, skin1; per-face B against all pairs through the exact form factor):
  //   epsilon_1 / epsilon_2   0.02/0.05   0.05/0.2    0.05/0.4    0.1/0.4
  //   links per triangle      311         97          64          48
  //   relative RMS of B       0.01-0.06%  0.15-0.5%   0.45-1.1%   1.6-2.8%
  // (the seed's Table 3: 44-53 links per triangle) with min_planarity 0.95; `near` moves the error
  // by < 0.1% between 0.01 and 0.05 sr and the link time by up to 5x, and 0.4 sr (point samples up
  // to epsilon_2) makes it 6-8%. On the same sphere squashed to 0.7 in x, planarity 0.95 lets the
  // analytic factor project curved clusters: 3.1% (marble); 0.99: 0.39% at 115 links per triangle
  // (the round sphere: 0.63%), 0.999: 0.32% at 213.
  double epsilon_1 = 0.05;  ///< receiver split: solid-angle deviation, sr
  double epsilon_2 = 0.4;   ///< emitter split: solid angle, sr
  double near = 0.05;       ///< above this solid angle (sr) a link uses the semi-analytic factor
  double min_planarity = 0.99;  ///< A' / A below which a near emitter cluster is split
  FormFactorOptions form_factor;
  Mode mode = Mode::kRender;
  long budget = 200000;  ///< kIncremental: link factors evaluated per frame (3 channels each)
  bool shadows = true;   ///< shadow rays from the leaves' midpoints toward each light
  /// Area lights: leaf irradiance from the per-cluster projection maps of Jacob 1993 (built once
  /// per light set and geometry, looked up every frame; render/core/irradiance_cache.h), texel
  /// the bounding radius / 64; false: 16 shadow rays per leaf every frame.
  bool irradiance_cache = true;
  /// Threads for the oracle and the links' factors (0: every core). The links, their order and B
  /// are the same for any number.
  int threads = 0;

  void validate() const;  ///< throws lucent::Error naming the option
  std::string to_string() const;
};

struct Stats {
  int triangles = 0, clusters = 0, depth = 0;
  long links = 0;            ///< stored (kOnTheFly: made in the last frame)
  long form_factor_calls = 0, point_samples = 0, edge_segments = 0;  ///< in the last frame
  long demoted = 0, promoted = 0, refreshed = 0;                      ///< kIncremental, last frame
  double build_ms = 0;  ///< the hierarchy
  /// What the solve holds, MiB: the hierarchy (clusters, boundary edges, welded vertices) and the
  /// stored links with their versions (none in kOnTheFly, whose links live one batch at a time).
  double memory_mib = 0;
  double link_ms = 0, irradiance_ms = 0, pull_ms = 0, gather_ms = 0, push_ms = 0;  ///< last frame
  double total_ms() const { return link_ms + irradiance_ms + pull_ms + gather_ms + push_ms; }
  std::string to_string() const;
};

/// The CPU side: hierarchy, links and the per-frame solve. Thread-compatible (one thread at a time).
class Solver {
 public:
  Solver(const Scene& scene, const Options& options);
  ~Solver();
  Solver(const Solver&) = delete;
  Solver& operator=(const Solver&) = delete;

  void set_lights(const std::vector<Light>& lights);
  void set_material(const materials::Material& material);
  /// Same vertices and triangles, new positions (mm) and unit normals.
  void set_geometry(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals);

  /// One frame of the chosen mode: (re)link as needed, irradiance, pull, gather, push.
  void solve();

  /// After solve(): B per mesh triangle and per mesh vertex (W mm^-2 per unit light), RGB.
  const std::vector<std::array<double, 3>>& face_B() const;
  const std::vector<std::array<double, 3>>& vertex_B() const;
  /// Irradiance E (F_t cos included) per mesh triangle, from the last solve.
  const std::vector<std::array<double, 3>>& face_E() const;
  const Hierarchy& hierarchy() const;
  const Stats& stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Reference for tests: B at each triangle's midpoint with every triangle as an emitter through
/// the semi-analytic form factor (all pairs, no hierarchy), for the irradiance `face_E`.
std::vector<std::array<double, 3>> all_pairs_B(const Mesh& mesh, const materials::Material& material,
                                               const std::vector<std::array<double, 3>>& face_E,
                                               const FormFactorOptions& options);

}  // namespace lucent::render::hierarchical
