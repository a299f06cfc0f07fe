// The hierarchical boundary-element solve (hierarchical.h): the oracle, the links of the three
// modes, and a frame's irradiance, pull, gather and push.
#include "lucent/render/hierarchical.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <numbers>
#include <optional>
#include <sstream>
#include <unordered_map>

#include "area_light_irradiance.h"
#include "irradiance_cache.h"
#include "lucent/core/error.h"
#include "lucent/materials/angular.h"
#include "lucent/materials/fresnel.h"
#include "lucent/materials/geometry_factor.h"
#include "lucent/materials/material.h"
#include "reference_common.h"

namespace lucent::render::hierarchical {

Mode parse_mode(const std::string& text) {
  if (text == "render") return Mode::kRender;
  if (text == "incremental") return Mode::kIncremental;
  if (text == "on-the-fly") return Mode::kOnTheFly;
  throw Error("--hierarchical-mode: expected render, incremental or on-the-fly, got '" + text +
              "'");
}

std::string to_string(Mode mode) {
  return mode == Mode::kRender ? "render" : mode == Mode::kIncremental ? "incremental" : "on-the-fly";
}

void Options::validate() const {
  auto positive = [](double v, const char* name) {
    if (!(v > 0) || !std::isfinite(v)) {
      throw Error(std::string(name) + ": expected a positive solid angle in sr, got " +
                  std::to_string(v));
    }
  };
  positive(epsilon_1, "--hierarchical-epsilon1");
  positive(epsilon_2, "--hierarchical-epsilon2");
  positive(near, "--hierarchical-near");
  if (!(min_planarity >= 0 && min_planarity <= 1)) {
    throw Error("--hierarchical-planarity: expected A'/A in [0, 1], got " +
                std::to_string(min_planarity));
  }
  if (!(form_factor.edge_constant > 0 && form_factor.edge_constant <= 2)) {
    throw Error("--hierarchical-edge-constant: expected a value in (0, 2] (the seed's 2/5), got " +
                std::to_string(form_factor.edge_constant));
  }
  if (budget < 1) throw Error("--hierarchical-budget: expected at least 1 form factor per frame");
}

std::string Options::to_string() const {
  std::ostringstream s;
  s << "mode " << hierarchical::to_string(mode) << ", epsilon_1 " << epsilon_1 << " sr, epsilon_2 "
    << epsilon_2 << " sr, near " << near << " sr, planarity " << min_planarity << ", edge c "
    << form_factor.edge_constant << " (" << hierarchical::to_string(form_factor.rule) << ", dipole "
    << hierarchical::to_string(form_factor.placement) << "), budget " << budget
    << ", irradiance cache " << (irradiance_cache ? "on" : "off");
  return s.str();
}

std::string Stats::to_string() const {
  std::ostringstream s;
  s << triangles << " triangles, " << clusters << " clusters (depth " << depth << "), " << links
    << " links, " << form_factor_calls << " form factors (" << edge_segments << " edge segments), "
    << point_samples << " point samples; ms: link " << link_ms << ", irradiance " << irradiance_ms
    << ", pull " << pull_ms << ", gather " << gather_ms << ", push " << push_ms;
  if (demoted || promoted || refreshed) {
    s << "; incremental: " << demoted << " demoted, " << promoted << " promoted, " << refreshed
      << " refreshed";
  }
  return s.str();
}

namespace {

using Coefficients = materials::DiffusionCoefficients<double>;
using Rgb = std::array<double, 3>;
using Clock = std::chrono::steady_clock;
// Shadow rays per face (or per cache grid vertex) for an area light (area_light_irradiance.h):
// with the control variate only faces whose horizon cuts the light are noisy; on a 100 mm sphere
// under a 50 mm rect the cache and per-leaf rays agree to 0.5% in E, 0.3% in B
// (hierarchical_solver_test).
constexpr int kAreaLightSamples = 16;

double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

struct Link {
  int R = 0, E = 0;
  Rgb F{};
};

enum class Decision { kSplitReceiver, kSplitEmitter, kLink };

}  // namespace

struct Solver::Impl {
  Scene scene;
  Options o;
  Hierarchy h;
  std::array<Coefficients, 3> c{};
  double eta = 1.3;
  std::unique_ptr<detail::RayScene> rays;
  std::unique_ptr<detail::IrradianceCache> cache;  // area lights, when o.irradiance_cache
  std::vector<Link> links;
  bool linked = false;
  std::uint64_t material_version = 0, geometry_version = 0;
  std::vector<std::uint64_t> link_material, link_geometry;  // versions each link was made at
  std::size_t cursor = 0;
  std::vector<Rgb> E, B, face_B, vertex_B, face_E;
  Stats stats;
  FormFactorCounters counters;
  long evaluations = 0;  // factor() calls

  void set_material(const materials::Material& m) {
    for (int ch = 0; ch < 3; ++ch) c[std::size_t(ch)] = materials::derive_coefficients(m.medium(ch));
    if (eta != m.ior) cache.reset();  // the cached E_t carries F_t(eta)
    eta = m.ior;
    angular.reset();
    if (scene.angular) angular.emplace(m);  // the shader applies the exit side
    ++material_version;
  }
  std::optional<materials::AngularFactor> angular;  // Scene::angular: the incidence side

  static double omega(const Eigen::Vector3d& x, const Cluster& e) {
    const double d = (x - e.midpoint).norm();
    const double a2 = e.area / std::numbers::pi;
    return 2 * std::numbers::pi * (1 - d / std::sqrt(d * d + a2));
  }

  Decision decide(int r, int e) const {
    const Cluster& R = h[r];
    const Cluster& Em = h[e];
    const double w = omega(R.midpoint, Em);
    if (!R.leaf()) {
      double deviation = 0;
      for (int ch : R.child) deviation = std::max(deviation, std::abs(omega(h[ch].midpoint, Em) - w));
      if (deviation > o.epsilon_1) return Decision::kSplitReceiver;
    }
    if (!Em.leaf()) {
      if (w > o.epsilon_2) return Decision::kSplitEmitter;
      if (w > o.near && Em.planarity() < o.min_planarity) return Decision::kSplitEmitter;
    }
    return Decision::kLink;
  }

  Rgb factor(int r, int e) {
    Rgb F = planar_factor(r, e);
    if (scene.geometry_factor) {  // the shape between the clusters (materials/geometry_factor.h)
      const Cluster& R = h[r];
      const Cluster& Em = h[e];
      for (int ch = 0; ch < 3; ++ch) {
        F[std::size_t(ch)] *= materials::GeometryFactor<double>(c[std::size_t(ch)])(
            Em.midpoint, Em.normal, R.midpoint, R.normal);
      }
    }
    return F;
  }

  Rgb planar_factor(int r, int e) {
    ++evaluations;
    const Cluster& R = h[r];
    const Cluster& Em = h[e];
    Rgb F{};
    if (omega(R.midpoint, Em) <= o.near) {
      for (int ch = 0; ch < 3; ++ch) {
        F[std::size_t(ch)] = point_form_factor(c[std::size_t(ch)], R.midpoint, R.normal,
                                               Em.midpoint, Em.area, o.form_factor.placement);
      }
      ++stats.point_samples;
      return F;
    }
    const auto& P = h.welded_positions();
    const auto& edges = h.boundary();
    const PlaneFrame plane = PlaneFrame::from_normal(Em.midpoint, Em.normal);
    std::vector<Vec2d> starts(std::size_t(Em.edge_count)), ends(std::size_t(Em.edge_count));
    for (int k = 0; k < Em.edge_count; ++k) {
      const auto& ed = edges[std::size_t(Em.first_edge + k)];
      starts[std::size_t(k)] = plane.project(P[std::size_t(ed[0])]);
      ends[std::size_t(k)] = plane.project(P[std::size_t(ed[1])]);
    }
    for (int ch = 0; ch < 3; ++ch) {
      F[std::size_t(ch)] = edges_form_factor(c[std::size_t(ch)], R.midpoint, R.normal, plane, starts,
                                             ends, o.form_factor, &counters);
    }
    return F;
  }

  // The oracle from (r, e) down; `emit` receives every link made.
  void refine(int r, int e, const std::function<void(int, int)>& emit) const {
    switch (decide(r, e)) {
      case Decision::kSplitReceiver:
        for (int ch : h[r].child) refine(ch, e, emit);
        return;
      case Decision::kSplitEmitter:
        for (int ch : h[e].child) refine(r, ch, emit);
        return;
      case Decision::kLink:
        emit(r, e);
    }
  }

  void link_all() {
    links.clear();
    refine(h.root(), h.root(), [&](int r, int e) { links.push_back({r, e, factor(r, e)}); });
    link_material.assign(links.size(), material_version);
    link_geometry.assign(links.size(), geometry_version);
    linked = true;
    cursor = 0;
  }

  // kIncremental: up to o.budget links re-checked from the cursor on. A link the oracle now splits
  // is replaced by its children's links (one level); a stale one gets a new factor; then links
  // whose receiver's siblings all link the same emitter and whose parent the oracle accepts are
  // merged into the parent's link (one level up).
  void repair() {
    const long before = evaluations;
    std::vector<Link> added;
    std::vector<char> removed(links.size(), 0);
    std::size_t visited = 0;
    while (visited < links.size() && evaluations - before < o.budget) {
      const std::size_t i = (cursor + visited) % links.size();
      ++visited;
      Link& l = links[i];
      if (link_material[i] == material_version && link_geometry[i] == geometry_version) continue;
      const Decision d = link_geometry[i] == geometry_version ? Decision::kLink : decide(l.R, l.E);
      if (d == Decision::kLink) {
        l.F = factor(l.R, l.E);
        link_material[i] = material_version;
        link_geometry[i] = geometry_version;
        ++stats.refreshed;
        continue;
      }
      removed[i] = 1;
      ++stats.demoted;
      const Cluster& split = h[d == Decision::kSplitReceiver ? l.R : l.E];
      for (int ch : split.child) {
        const int r = d == Decision::kSplitReceiver ? ch : l.R;
        const int e = d == Decision::kSplitReceiver ? l.E : ch;
        added.push_back({r, e, factor(r, e)});
      }
    }
    cursor = links.empty() ? 0 : (cursor + visited) % links.size();
    // Promotion, one level: (c0, E) and (c1, E) with c0, c1 the children of P become (P, E) when
    // the oracle links (P, E); likewise (R, c0) and (R, c1) become (R, Q) for E's side.
    for (int side = 0; side < 2; ++side) {
      std::unordered_map<std::uint64_t, std::array<int, 2>> siblings;  // (parent, other) -> links
      for (std::size_t i = 0; i < links.size(); ++i) {
        if (removed[i] || link_geometry[i] != geometry_version) continue;
        const int moving = side == 0 ? links[i].R : links[i].E;
        const int other = side == 0 ? links[i].E : links[i].R;
        const int p = h[moving].parent;
        if (p < 0) continue;
        const std::uint64_t key = (std::uint64_t(std::uint32_t(p)) << 32) | std::uint32_t(other);
        auto [it, inserted] = siblings.emplace(key, std::array<int, 2>{int(i), -1});
        if (inserted) continue;
        const Link& first = links[std::size_t(it->second[0])];
        if ((side == 0 ? first.R : first.E) != moving) it->second[1] = int(i);
      }
      for (const auto& [key, pair] : siblings) {
        if (pair[1] < 0) continue;
        const int p = int(key >> 32), other = int(key & 0xffffffffu);
        const int r = side == 0 ? p : other, e = side == 0 ? other : p;
        if (decide(r, e) != Decision::kLink) continue;
        removed[std::size_t(pair[0])] = removed[std::size_t(pair[1])] = 1;
        added.push_back({r, e, factor(r, e)});
        ++stats.promoted;
      }
    }
    std::vector<Link> kept;
    std::vector<std::uint64_t> km, kg;
    kept.reserve(links.size() + added.size());
    for (std::size_t i = 0; i < links.size(); ++i) {
      if (removed[i]) continue;
      kept.push_back(links[i]);
      km.push_back(link_material[i]);
      kg.push_back(link_geometry[i]);
    }
    for (const Link& l : added) {
      kept.push_back(l);
      km.push_back(material_version);
      kg.push_back(geometry_version);
    }
    links = std::move(kept);
    link_material = std::move(km);
    link_geometry = std::move(kg);
  }

  void irradiance() {
    const Mesh& mesh = scene.mesh;
    const float eps = 1e-4f * std::max(mesh.bounding_radius(), 1e-6f);
    const std::size_t T = mesh.triangles.size();
    face_E.assign(T, Rgb{});
    const bool any_area = std::any_of(scene.lights.begin(), scene.lights.end(),
                                      [](const Light& l) { return l.type == LightType::kArea; });
    if (any_area && o.irradiance_cache && !cache) {
      detail::IrradianceCacheOptions co;
      co.shadow_samples = kAreaLightSamples;
      co.shadows = o.shadows;
      co.coat = scene.fur_coat ? &*scene.fur_coat : nullptr;
      cache = std::make_unique<detail::IrradianceCache>(mesh, scene.lights, rays.get(), eta, co);
    }
    for (std::size_t t = 0; t < T; ++t) {
      const auto& tri = mesh.triangles[t];
      const Vec3f &a = mesh.positions[tri[0]], &b = mesh.positions[tri[1]],
                  &d = mesh.positions[tri[2]];
      const Vec3f x = (a + b + d) / 3.0f;
      Vec3f g = (b - a).cross(d - a);
      if (!(g.norm() > 0)) continue;
      g.normalize();
      Vec3f n = mesh.normals[tri[0]] + mesh.normals[tri[1]] + mesh.normals[tri[2]];
      n = n.norm() > 0 ? Vec3f(n.normalized()) : g;
      if (cache) {
        const auto E = cache->lookup(t, x);
        for (int ch = 0; ch < 3; ++ch) face_E[t][std::size_t(ch)] += std::max(E[std::size_t(ch)], 0.0);
      }
      for (std::size_t l = 0; l < scene.lights.size(); ++l) {
        const Light& light = scene.lights[l];
        if (light.type == LightType::kArea) {
          if (cache) continue;
          // kAreaLightSamples stratified shadow rays with the analytic pi F as control variate
          // (area_light_irradiance.h), the same points every frame (no flicker); a penumbra's
          // rare negative estimate is clamped to 0.
          detail::AreaLightSampling sampling;
          sampling.samples = kAreaLightSamples;
          sampling.shadows = o.shadows;
          sampling.coat = scene.fur_coat ? &*scene.fur_coat : nullptr;
          const detail::AreaIrradiance a = detail::area_light_irradiance(
              light, x, n, g, rays.get(), eps, eta, sampling,
              detail::mix(std::uint64_t(t) * 0x9E3779B97F4A7C15ull + l));
          const double f = std::max(a.transmitted, 0.0);
          const double cos_a = double(n.dot(a.w));
          for (int ch = 0; ch < 3; ++ch)
            face_E[t][std::size_t(ch)] +=
                f * light.radiance[ch] * (angular ? (*angular)(ch, cos_a) : 1.0);
          continue;
        }
        Vec3f w;
        double falloff = 1, distance = detail::kInf;
        if (!detail::toward_light(light, x, w, falloff, distance)) continue;
        const double cos_i = n.dot(w);
        if (!(cos_i > 0)) continue;
        if (o.shadows) {
          const Vec3f offset = g.dot(w) >= 0 ? g : Vec3f(-g);
          if (rays->occluded(x + eps * offset, w, distance - eps)) continue;
        }
        const double f = falloff * cos_i * materials::fresnel_transmittance(cos_i, eta) *
                         (scene.fur_coat ? scene.fur_coat->at(cos_i) : 1.0);
        for (int ch = 0; ch < 3; ++ch)
          face_E[t][std::size_t(ch)] +=
              f * light.radiance[ch] * (angular ? (*angular)(ch, cos_i) : 1.0);
      }
    }
  }

  void frame() {
    stats.form_factor_calls = stats.point_samples = stats.edge_segments = 0;
    stats.demoted = stats.promoted = stats.refreshed = 0;
    counters = {};
    auto t0 = Clock::now();
    if (o.mode != Mode::kOnTheFly) {
      if (!linked || o.mode == Mode::kRender) {
        if (!linked || material_version_seen != material_version ||
            geometry_version_seen != geometry_version) {
          link_all();
        }
      } else {
        repair();
      }
      material_version_seen = material_version;
      geometry_version_seen = geometry_version;
    }
    stats.link_ms = ms_since(t0);

    t0 = Clock::now();
    irradiance();
    stats.irradiance_ms = ms_since(t0);

    t0 = Clock::now();
    const std::size_t n = h.clusters().size();
    E.assign(n, Rgb{});
    B.assign(n, Rgb{});
    for (std::size_t t = 0; t < face_E.size(); ++t) E[std::size_t(h.leaf_of_face(int(t)))] = face_E[t];
    // Clusters are created after their children: increasing ids are a bottom-up order.
    for (std::size_t id = face_E.size(); id < n; ++id) {
      const Cluster& cl = h.clusters()[id];
      const Cluster& a = h[cl.child[0]];
      const Cluster& b = h[cl.child[1]];
      for (int ch = 0; ch < 3; ++ch) {
        E[id][std::size_t(ch)] =
            cl.area > 0 ? (a.area * E[std::size_t(cl.child[0])][std::size_t(ch)] +
                           b.area * E[std::size_t(cl.child[1])][std::size_t(ch)]) / cl.area
                        : 0;
      }
    }
    stats.pull_ms = ms_since(t0);

    t0 = Clock::now();
    auto gather = [&](int r, int e, const Rgb& F) {
      for (int ch = 0; ch < 3; ++ch) {
        B[std::size_t(r)][std::size_t(ch)] += F[std::size_t(ch)] * E[std::size_t(e)][std::size_t(ch)];
      }
    };
    if (o.mode == Mode::kOnTheFly) {
      long made = 0;
      refine(h.root(), h.root(), [&](int r, int e) {
        ++made;
        gather(r, e, factor(r, e));
      });
      stats.links = made;
    } else {
      for (const Link& l : links) gather(l.R, l.E, l.F);
      stats.links = long(links.size());
    }
    stats.gather_ms = ms_since(t0);
    stats.form_factor_calls = counters.calls;
    stats.edge_segments = counters.segments;

    t0 = Clock::now();
    // Push: parents before children (decreasing ids), each child adds its parent's B.
    for (std::size_t id = n; id-- > face_E.size();) {
      const Cluster& cl = h.clusters()[id];
      for (int child : cl.child)
        for (int ch = 0; ch < 3; ++ch) {
          B[std::size_t(child)][std::size_t(ch)] += B[id][std::size_t(ch)];
        }
    }
    const Mesh& mesh = scene.mesh;
    face_B.assign(mesh.triangles.size(), Rgb{});
    for (std::size_t t = 0; t < face_B.size(); ++t) face_B[t] = B[std::size_t(h.leaf_of_face(int(t)))];
    // Per vertex: area-weighted over the faces around each welded vertex (smooth across seams).
    const auto& weld = h.weld();
    std::vector<Rgb> sum(h.welded_positions().size(), Rgb{});
    std::vector<double> area(sum.size(), 0);
    for (std::size_t t = 0; t < face_B.size(); ++t) {
      const double a = h[h.leaf_of_face(int(t))].area;
      for (unsigned v : mesh.triangles[t]) {
        const std::size_t w = std::size_t(weld[v]);
        area[w] += a;
        for (int ch = 0; ch < 3; ++ch) sum[w][std::size_t(ch)] += a * face_B[t][std::size_t(ch)];
      }
    }
    vertex_B.assign(mesh.positions.size(), Rgb{});
    for (std::size_t v = 0; v < vertex_B.size(); ++v) {
      const std::size_t w = std::size_t(weld[v]);
      if (area[w] > 0)
        for (int ch = 0; ch < 3; ++ch) vertex_B[v][std::size_t(ch)] = sum[w][std::size_t(ch)] / area[w];
    }
    stats.push_ms = ms_since(t0);
  }

  std::uint64_t material_version_seen = ~std::uint64_t(0), geometry_version_seen = ~std::uint64_t(0);
};

Solver::Solver(const Scene& scene, const Options& options) : impl_(std::make_unique<Impl>()) {
  options.validate();
  Impl& m = *impl_;
  m.scene = scene;
  m.o = options;
  const auto t0 = Clock::now();
  m.h = Hierarchy::build(scene.mesh);
  m.stats.build_ms = ms_since(t0);
  m.stats.triangles = int(scene.mesh.triangles.size());
  m.stats.clusters = int(m.h.clusters().size());
  m.stats.depth = m.h.depth();
  m.rays = std::make_unique<detail::RayScene>(scene.mesh);
  m.set_material(scene.material);
}

Solver::~Solver() = default;

void Solver::set_lights(const std::vector<Light>& lights) {
  impl_->scene.lights = lights;
  impl_->cache.reset();
}

void Solver::set_material(const materials::Material& material) {
  impl_->scene.material = material;
  impl_->set_material(material);
}

void Solver::set_geometry(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals) {
  Impl& m = *impl_;
  if (positions.size() != m.scene.mesh.positions.size() || normals.size() != positions.size()) {
    throw Error("hierarchical: new geometry has " + std::to_string(positions.size()) +
                " vertices, the mesh " + std::to_string(m.scene.mesh.positions.size()));
  }
  m.scene.mesh.positions = positions;
  m.scene.mesh.normals = normals;
  m.h.update_geometry(positions);
  m.rays = std::make_unique<detail::RayScene>(m.scene.mesh);
  m.cache.reset();
  ++m.geometry_version;
}

void Solver::solve() { impl_->frame(); }

const std::vector<std::array<double, 3>>& Solver::face_B() const { return impl_->face_B; }
const std::vector<std::array<double, 3>>& Solver::vertex_B() const { return impl_->vertex_B; }
const std::vector<std::array<double, 3>>& Solver::face_E() const { return impl_->face_E; }
const Hierarchy& Solver::hierarchy() const { return impl_->h; }
const Stats& Solver::stats() const { return impl_->stats; }

std::vector<std::array<double, 3>> all_pairs_B(const Mesh& mesh, const materials::Material& material,
                                               const std::vector<std::array<double, 3>>& face_E,
                                               const FormFactorOptions& options) {
  std::array<Coefficients, 3> c{};
  for (int ch = 0; ch < 3; ++ch) c[std::size_t(ch)] = materials::derive_coefficients(material.medium(ch));
  const std::size_t T = mesh.triangles.size();
  std::vector<Eigen::Vector3d> mid(T), normal(T);
  for (std::size_t t = 0; t < T; ++t) {
    const auto& tri = mesh.triangles[t];
    const Eigen::Vector3d a = mesh.positions[tri[0]].cast<double>(),
                          b = mesh.positions[tri[1]].cast<double>(),
                          d = mesh.positions[tri[2]].cast<double>();
    mid[t] = (a + b + d) / 3;
    const Eigen::Vector3d n = (b - a).cross(d - a);
    normal[t] = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::UnitZ();
  }
  std::vector<std::array<double, 3>> B(T, Rgb{});
  for (std::size_t r = 0; r < T; ++r) {
    for (std::size_t e = 0; e < T; ++e) {
      const auto& tri = mesh.triangles[e];
      for (int ch = 0; ch < 3; ++ch) {
        if (face_E[e][std::size_t(ch)] == 0) continue;
        B[r][std::size_t(ch)] +=
            face_E[e][std::size_t(ch)] *
            triangle_form_factor(c[std::size_t(ch)], mid[r], normal[r],
                                 mesh.positions[tri[0]].cast<double>(),
                                 mesh.positions[tri[1]].cast<double>(),
                                 mesh.positions[tri[2]].cast<double>(), options);
      }
    }
  }
  return B;
}

}  // namespace lucent::render::hierarchical
