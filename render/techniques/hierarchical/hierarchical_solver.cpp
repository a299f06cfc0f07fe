// The hierarchical boundary-element solve (hierarchical.h): the oracle, the links of the three
// modes, and a frame's irradiance, pull, gather and push.
#include "lucent/render/hierarchical.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <mutex>
#include <numbers>
#include <optional>
#include <queue>
#include <sstream>
#include <thread>
#include <unordered_map>

#include "area_light_irradiance.h"
#include "hierarchical_irradiance.h"
#include "irradiance_cache.h"
#include "lucent/core/error.h"
#include "lucent/materials/angular.h"
#include "lucent/materials/fresnel.h"
#include "lucent/materials/geometry_factor.h"
#include "lucent/materials/material.h"
#include "reference_common.h"

namespace lucent::render::hierarchical {

namespace {

using Coefficients = materials::DiffusionCoefficients<double>;
using Rgb = std::array<double, 3>;
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// A link's factor is kept in single precision (B is summed in double): 20 bytes a link, where
// the dragon:3 makes 15 million.
struct Link {
  int R = 0, E = 0;
  std::array<float, 3> F{};
};

// What the factor evaluations of one thread counted, added into the frame's stats after.
struct Tally {
  long evaluations = 0, point_samples = 0;
  FormFactorCounters form_factor;
  void add(const Tally& t) {
    evaluations += t.evaluations;
    point_samples += t.point_samples;
    form_factor.calls += t.form_factor.calls;
    form_factor.segments += t.form_factor.segments;
  }
};

// The oracle's work is handed to threads as subproblems (R, E) of at most 2 / kOracleTasks of the
// mesh's faces each (oracle_tasks; fixed, so that the links and their order, and so B to the last
// bit, do not depend on the number of threads). On dragon:4 16 gives 71k subproblems (the pairs the
// oracle links on the way are subproblems of one link), the largest 1% of the links, and links on
// 2 threads in 0.51 of 1 thread's time; 64 and 256 make 230k and 828k, whose overhead costs 4% and
// 25% (a level-wise split left two subproblems of a third of the links: 0.7 of the time).
constexpr std::size_t kOracleTasks = 16;
// Subproblems linked at once in on-the-fly frames: their links are the only ones held in memory
// at a time.
constexpr std::size_t kTaskBatch = 512;

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
  std::uint32_t material_version = 0, geometry_version = 0;
  int threads = 1;
  std::vector<std::uint32_t> link_material, link_geometry;  // versions each link was made at
  std::size_t cursor = 0;
  std::size_t stale_links = 0;  // kIncremental: links made at an older material or geometry
  std::vector<Rgb> E, B, face_B, vertex_B, face_E;
  Stats stats;
  Tally tally;  // the frame's factor evaluations

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

  std::array<float, 3> factor(int r, int e, Tally& t) const {
    const Rgb F = full_factor(r, e, t);
    return {float(F[0]), float(F[1]), float(F[2])};
  }

  Rgb full_factor(int r, int e, Tally& t) const {
    Rgb F = planar_factor(r, e, t);
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

  Rgb planar_factor(int r, int e, Tally& t) const {
    ++t.evaluations;
    const Cluster& R = h[r];
    const Cluster& Em = h[e];
    Rgb F{};
    if (omega(R.midpoint, Em) <= o.near) {
      for (int ch = 0; ch < 3; ++ch) {
        F[std::size_t(ch)] = point_form_factor(c[std::size_t(ch)], R.midpoint, R.normal,
                                               Em.midpoint, Em.area, o.form_factor.placement);
      }
      ++t.point_samples;
      return F;
    }
    const auto& P = h.welded_positions();
    const auto& edges = h.boundary();
    const PlaneFrame plane = PlaneFrame::from_normal(Em.midpoint, Em.normal);
    thread_local std::vector<Vec2d> starts, ends;
    starts.resize(std::size_t(Em.edge_count));
    ends.resize(std::size_t(Em.edge_count));
    for (int k = 0; k < Em.edge_count; ++k) {
      const auto& ed = edges[std::size_t(Em.first_edge + k)];
      starts[std::size_t(k)] = plane.project(P[std::size_t(ed[0])]);
      ends[std::size_t(k)] = plane.project(P[std::size_t(ed[1])]);
    }
    return edges_form_factor_rgb(c, R.midpoint, R.normal, plane, starts, ends, o.form_factor,
                                 &t.form_factor);
  }

  // The oracle from (r, e) down; `emit` receives every link made, depth first.
  template <class Emit>
  void refine(int r, int e, Emit& emit) const {
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

  // The oracle's subproblems for the threads: from (root, root), the pair with the most faces
  // between its two clusters is split as the oracle splits it (a pair it links is a subproblem of
  // one link), until no pair holds more than 2 / kOracleTasks of the mesh's faces. Splitting
  // by size, not by depth, matters on an unbalanced hierarchy (dragon:4's is 30 deep: a level-wise
  // split left two subproblems with a third of the links). The tasks are then in (R, E) order:
  // the same tasks and links whatever the number of threads.
  std::vector<std::array<int, 2>> oracle_tasks() const {
    using Entry = std::array<int, 3>;  // faces of R + faces of E, R, E
    const auto faces = [&](int r, int e) { return h[r].face_count + h[e].face_count; };
    const int limit = std::max(2, 2 * h[h.root()].face_count / int(kOracleTasks));
    std::priority_queue<Entry> open;
    std::vector<std::array<int, 2>> tasks;
    open.push({faces(h.root(), h.root()), h.root(), h.root()});
    while (!open.empty()) {
      const auto [size, r, e] = open.top();
      if (size <= limit) break;
      open.pop();
      const Decision d = decide(r, e);
      if (d == Decision::kLink) {
        tasks.push_back({r, e});
        continue;
      }
      for (int ch : h[d == Decision::kSplitReceiver ? r : e].child) {
        const int rr = d == Decision::kSplitReceiver ? ch : r,
                  ee = d == Decision::kSplitReceiver ? e : ch;
        open.push({faces(rr, ee), rr, ee});
      }
    }
    for (; !open.empty(); open.pop()) tasks.push_back({open.top()[1], open.top()[2]});
    std::sort(tasks.begin(), tasks.end());
    return tasks;
  }

  // The links of tasks [begin, end) with their factors, each task's in depth-first order, one
  // task a work item; `out[k]` receives task begin + k's.
  void make_links(const std::vector<std::array<int, 2>>& tasks, std::size_t begin, std::size_t end,
                  std::vector<std::vector<Link>>& out) {
    out.resize(end - begin);
    std::mutex mutex;
    detail::parallel_for(end - begin, threads, 1, [&](std::size_t b, std::size_t e) {
      Tally local;
      for (std::size_t k = b; k < e; ++k) {
        std::vector<Link>& made = out[k];
        made.clear();
        auto emit = [&](int r, int em) { made.push_back({r, em, factor(r, em, local)}); };
        refine(tasks[begin + k][0], tasks[begin + k][1], emit);
      }
      const std::lock_guard<std::mutex> lock(mutex);
      tally.add(local);
    });
  }

  // Every link from scratch, on `threads` threads: the same links in the same order whatever
  // their number.
  void link_all() {
    links.clear();
    const std::vector<std::array<int, 2>> tasks = oracle_tasks();
    std::vector<std::vector<Link>> made;
    make_links(tasks, 0, tasks.size(), made);
    std::size_t total = 0;
    for (const auto& m : made) total += m.size();
    links.reserve(total);
    for (auto& m : made) {
      links.insert(links.end(), m.begin(), m.end());
      std::vector<Link>().swap(m);
    }
    stale_links = 0;
    link_material.assign(links.size(), material_version);
    link_geometry.assign(links.size(), geometry_version);
    linked = true;
    cursor = 0;
  }

  // Factors for planned links, in parallel: `targets[k]` gets the factor of its own (R, E).
  void evaluate(const std::vector<Link*>& targets) {
    std::mutex mutex;
    detail::parallel_for(targets.size(), threads, 64, [&](std::size_t b, std::size_t e) {
      Tally local;
      for (std::size_t k = b; k < e; ++k)
        targets[k]->F = factor(targets[k]->R, targets[k]->E, local);
      const std::lock_guard<std::mutex> lock(mutex);
      tally.add(local);
    });
  }

  // kIncremental: up to o.budget links re-checked from the cursor on. A link the oracle now splits
  // is replaced by its children's links (one level); a stale one gets a new factor; then links
  // whose receiver's siblings all link the same emitter and whose parent the oracle accepts are
  // merged into the parent's link (one level up).
  // The links to re-evaluate are chosen first (the oracle is cheap) and their factors evaluated
  // after, in parallel.
  void repair() {
    if (stale_links == 0) return;  // nothing changed since the links were last repaired
    long planned = 0;              // factor evaluations, promotions' included
    std::vector<Link> added;
    std::vector<std::size_t> refresh;
    std::vector<char> removed(links.size(), 0);
    std::size_t visited = 0;
    while (visited < links.size() && planned < o.budget) {
      const std::size_t i = (cursor + visited) % links.size();
      ++visited;
      Link& l = links[i];
      if (link_material[i] == material_version && link_geometry[i] == geometry_version) continue;
      --stale_links;
      const Decision d = link_geometry[i] == geometry_version ? Decision::kLink : decide(l.R, l.E);
      if (d == Decision::kLink) {
        refresh.push_back(i);
        ++planned;
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
        added.push_back({r, e, {}});
        ++planned;
      }
    }
    const std::size_t window = cursor;
    const std::size_t next = links.empty() ? 0 : (cursor + visited) % links.size();
    // Promotion, one level: (c0, E) and (c1, E) with c0, c1 the children of P become (P, E) when
    // the oracle links (P, E); likewise (R, c0) and (R, c1) become (R, Q) for E's side. Among the
    // links this frame visited (the oracle makes siblings' links one after the other), within the
    // budget, so that a frame costs its budget, not the number of links.
    for (int side = 0; side < 2; ++side) {
      std::unordered_map<std::uint64_t, std::array<int, 2>> siblings;  // (parent, other) -> links
      for (std::size_t k = 0; k < visited; ++k) {
        const std::size_t i = (window + k) % links.size();
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
        if (planned >= o.budget) break;
        if (decide(r, e) != Decision::kLink) continue;
        removed[std::size_t(pair[0])] = removed[std::size_t(pair[1])] = 1;
        ++planned;
        added.push_back({r, e, {}});
        ++stats.promoted;
      }
    }
    std::vector<Link*> targets;
    targets.reserve(refresh.size() + added.size());
    for (std::size_t i : refresh)
      if (!removed[i]) targets.push_back(&links[i]);  // not if promoted away since
    for (Link& l : added) targets.push_back(&l);
    evaluate(targets);
    // The removed links compacted away in place (in order), the new ones appended; the cursor
    // follows the first link not visited to its new index.
    std::size_t kept = 0;
    cursor = 0;
    for (std::size_t i = 0; i < links.size(); ++i) {
      if (i == next) cursor = kept;
      if (removed[i]) continue;
      if (kept != i) {
        links[kept] = links[i];
        link_material[kept] = link_material[i];
        link_geometry[kept] = link_geometry[i];
      }
      ++kept;
    }
    if (cursor >= kept) cursor = 0;
    links.resize(kept);
    link_material.resize(kept);
    link_geometry.resize(kept);
    for (const Link& l : added) {
      links.push_back(l);
      link_material.push_back(material_version);
      link_geometry.push_back(geometry_version);
    }
  }

  double memory_mib() const {
    const double hierarchy = double(h.clusters().size() * sizeof(Cluster) +
                                    h.boundary().size() * sizeof(h.boundary()[0]) +
                                    h.welded_positions().size() * sizeof(Eigen::Vector3d) +
                                    (h.faces().size() + h.weld().size()) * sizeof(int));
    const double stored =
        double(links.capacity() * sizeof(Link) +
               (link_material.capacity() + link_geometry.capacity()) * sizeof(std::uint32_t));
    return (hierarchy + stored) / (1024.0 * 1024.0);
  }

  void irradiance() {
    leaf_irradiance(scene, o.shadows, o.irradiance_cache, eta, angular ? &*angular : nullptr,
                    rays.get(), cache, face_E);
  }

  void frame() {
    stats.form_factor_calls = stats.point_samples = stats.edge_segments = 0;
    stats.demoted = stats.promoted = stats.refreshed = 0;
    tally = {};
    auto t0 = Clock::now();
    if (o.mode != Mode::kOnTheFly) {
      if (!linked || o.mode == Mode::kRender) {
        if (!linked || material_version_seen != material_version ||
            geometry_version_seen != geometry_version) {
          link_all();
        }
      } else {
        // A new material or geometry makes every link stale (each keeps the versions it was made
        // at); repair() takes them a budget at a time.
        if (material_version_seen != material_version || geometry_version_seen != geometry_version)
          stale_links = links.size();
        repair();
      }
      material_version_seen = material_version;
      geometry_version_seen = geometry_version;
    }
    stats.link_ms = ms_since(t0);
    stats.memory_mib = memory_mib();

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
    auto gather = [&](int r, int e, const std::array<float, 3>& F) {
      for (int ch = 0; ch < 3; ++ch) {
        B[std::size_t(r)][std::size_t(ch)] += F[std::size_t(ch)] * E[std::size_t(e)][std::size_t(ch)];
      }
    };
    if (o.mode == Mode::kOnTheFly) {
      // No links kept: a batch of the oracle's subproblems at a time, linked in parallel and
      // gathered in order (the same sums as the render mode's).
      long made = 0;
      const std::vector<std::array<int, 2>> tasks = oracle_tasks();
      std::vector<std::vector<Link>> batch;
      for (std::size_t begin = 0; begin < tasks.size(); begin += kTaskBatch) {
        make_links(tasks, begin, std::min(tasks.size(), begin + kTaskBatch), batch);
        for (const auto& links_made : batch) {
          for (const Link& l : links_made) gather(l.R, l.E, l.F);
          made += long(links_made.size());
        }
      }
      stats.links = made;
    } else {
      for (const Link& l : links) gather(l.R, l.E, l.F);
      stats.links = long(links.size());
    }
    stats.gather_ms = ms_since(t0);
    stats.form_factor_calls = tally.form_factor.calls;
    stats.edge_segments = tally.form_factor.segments;
    stats.point_samples = tally.point_samples;

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
  m.threads = options.threads > 0 ? options.threads
                                  : int(std::max(1u, std::thread::hardware_concurrency()));
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

}  // namespace lucent::render::hierarchical
