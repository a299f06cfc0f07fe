// Bottom-up face clustering (hierarchical_clusters.h): level by level, each cluster (smallest
// first) is merged with the unmatched neighbour that keeps the pair most compact, radius^2 / area
// of the union; a level that finds no neighbour to merge joins the nearest clusters instead (parts
// of the mesh that share no edge).
#include "lucent/render/hierarchical_clusters.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>
#include <unordered_map>
#include <unordered_set>

#include "lucent/core/error.h"

namespace lucent::render::hierarchical {
namespace {

using Vec3d = Eigen::Vector3d;

std::uint64_t edge_key(int a, int b) {
  return (std::uint64_t(std::uint32_t(std::min(a, b))) << 32) | std::uint32_t(std::max(a, b));
}

struct PositionHash {
  std::size_t operator()(const std::array<float, 3>& p) const {
    std::uint32_t b[3];
    std::memcpy(b, p.data(), sizeof b);
    return std::hash<std::uint64_t>()((std::uint64_t(b[0]) * 73856093u) ^
                                      (std::uint64_t(b[1]) * 19349663u) ^
                                      (std::uint64_t(b[2]) * 83492791u));
  }
};

// The union of two clusters' spheres about their area-weighted midpoint.
void merged_sphere(const Cluster& a, const Cluster& b, Vec3d& midpoint, double& radius,
                   double& area) {
  area = a.area + b.area;
  midpoint = area > 0 ? Vec3d((a.area * a.midpoint + b.area * b.midpoint) / area)
                      : Vec3d(0.5 * (a.midpoint + b.midpoint));
  radius = std::max((a.midpoint - midpoint).norm() + a.radius,
                    (b.midpoint - midpoint).norm() + b.radius);
}

double merge_cost(const Cluster& a, const Cluster& b) {
  Vec3d m;
  double r, area;
  merged_sphere(a, b, m, r, area);
  return r * r / std::max(area, 1e-300);
}

// Each face's neighbours across its edges (welded vertex indices).
std::vector<std::vector<int>> face_adjacency(const std::vector<std::array<int, 3>>& triangles) {
  const int T = int(triangles.size());
  std::unordered_map<std::uint64_t, std::vector<int>> edge_faces;
  edge_faces.reserve(std::size_t(3 * T));
  for (int t = 0; t < T; ++t) {
    const auto& w = triangles[std::size_t(t)];
    for (int k = 0; k < 3; ++k)
      edge_faces[edge_key(w[std::size_t(k)], w[std::size_t((k + 1) % 3)])].push_back(t);
  }
  std::vector<std::vector<int>> adjacency(static_cast<std::size_t>(T));
  for (const auto& [key, faces] : edge_faces) {
    for (int a : faces)
      for (int b : faces)
        if (a != b) adjacency[std::size_t(a)].push_back(b);
  }
  return adjacency;
}

}  // namespace

Hierarchy Hierarchy::build(const Mesh& mesh) {
  if (mesh.triangles.empty()) throw Error("hierarchical: the mesh has no triangles");
  Hierarchy h;
  h.weld_vertices(mesh);
  const int T = int(mesh.triangles.size());
  // Leaves: cluster t is triangle t.
  h.clusters_.resize(std::size_t(T));
  h.leaf_of_face_.resize(std::size_t(T));
  std::iota(h.leaf_of_face_.begin(), h.leaf_of_face_.end(), 0);
  h.update_geometry(mesh.positions);  // leaves only so far (no parents yet)
  h.merge_levels(face_adjacency(h.welded_triangles_));
  h.order_depth_first();
  h.build_boundaries();
  h.update_geometry(mesh.positions);
  return h;
}

void Hierarchy::weld_vertices(const Mesh& mesh) {
  // Weld vertices by position: neighbours are found across split normals and UV seams.
  std::unordered_map<std::array<float, 3>, int, PositionHash> ids;
  weld_.resize(mesh.positions.size());
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const std::array<float, 3> p = {mesh.positions[v].x(), mesh.positions[v].y(),
                                    mesh.positions[v].z()};
    auto [it, inserted] = ids.emplace(p, int(welded_.size()));
    if (inserted) welded_.push_back(mesh.positions[v].cast<double>());
    weld_[v] = it->second;
  }
  const int T = int(mesh.triangles.size());
  welded_triangles_.resize(std::size_t(T));
  for (int t = 0; t < T; ++t) {
    for (int k = 0; k < 3; ++k) {
      welded_triangles_[std::size_t(t)][std::size_t(k)] =
          weld_[mesh.triangles[std::size_t(t)][std::size_t(k)]];
    }
  }
}

void Hierarchy::merge_levels(std::vector<std::vector<int>> adjacency) {
  const int T = int(welded_triangles_.size());
  std::vector<int> current(static_cast<std::size_t>(T));
  std::iota(current.begin(), current.end(), 0);
  auto make_parent = [&](int a, int b) {
    Cluster p;
    p.child = {a, b};
    merged_sphere(clusters_[std::size_t(a)], clusters_[std::size_t(b)], p.midpoint, p.radius,
                  p.area);
    const int id = int(clusters_.size());
    clusters_[std::size_t(a)].parent = id;
    clusters_[std::size_t(b)].parent = id;
    clusters_.push_back(p);
    adjacency.emplace_back();
    return id;
  };
  while (current.size() > 1) {
    std::sort(current.begin(), current.end(), [&](int a, int b) {
      const double aa = clusters_[std::size_t(a)].area, ab = clusters_[std::size_t(b)].area;
      return aa != ab ? aa < ab : a < b;
    });
    std::unordered_set<int> in_level(current.begin(), current.end()), matched;
    std::vector<int> next;
    next.reserve(current.size() / 2 + 1);
    for (int a : current) {
      if (matched.count(a)) continue;
      int best = -1;
      double best_cost = std::numeric_limits<double>::infinity();
      for (int b : adjacency[std::size_t(a)]) {
        if (b == a || matched.count(b) || !in_level.count(b)) continue;
        const double cost = merge_cost(clusters_[std::size_t(a)], clusters_[std::size_t(b)]);
        if (cost < best_cost || (cost == best_cost && b < best)) {
          best_cost = cost;
          best = b;
        }
      }
      matched.insert(a);
      if (best < 0) {
        next.push_back(a);
        continue;
      }
      matched.insert(best);
      next.push_back(make_parent(a, best));
    }
    if (next.size() == current.size()) {
      // No cluster has a neighbour left: join each with the nearest unmatched one.
      next.clear();
      std::vector<char> used(current.size(), 0);
      for (std::size_t i = 0; i < current.size(); ++i) {
        if (used[i]) continue;
        used[i] = 1;
        std::size_t best = current.size();
        double best_d = std::numeric_limits<double>::infinity();
        for (std::size_t j = 0; j < current.size(); ++j) {
          if (used[j]) continue;
          const double d = (clusters_[std::size_t(current[i])].midpoint -
                            clusters_[std::size_t(current[j])].midpoint)
                               .squaredNorm();
          if (d < best_d) {
            best_d = d;
            best = j;
          }
        }
        if (best == current.size()) {
          next.push_back(current[i]);
        } else {
          used[best] = 1;
          next.push_back(make_parent(current[i], current[best]));
        }
      }
    }
    // The new level's adjacency: the children's neighbours, lifted to their clusters.
    auto top = [&](int c) {
      while (clusters_[std::size_t(c)].parent >= 0) c = clusters_[std::size_t(c)].parent;
      return c;
    };
    for (int p : next) {
      const Cluster& cp = clusters_[std::size_t(p)];
      if (cp.leaf() || !adjacency[std::size_t(p)].empty()) continue;
      std::unordered_set<int> neighbours;
      for (int c : cp.child)
        for (int n : adjacency[std::size_t(c)]) {
          const int t = top(n);
          if (t != p) neighbours.insert(t);
        }
      adjacency[std::size_t(p)].assign(neighbours.begin(), neighbours.end());
      std::sort(adjacency[std::size_t(p)].begin(), adjacency[std::size_t(p)].end());
    }
    current = std::move(next);
  }
  root_ = current[0];
}

void Hierarchy::order_depth_first() {
  const int T = int(welded_triangles_.size());
  // Depth-first order: face ranges, depths, the post-order for bottom-up passes.
  faces_.clear();
  faces_.reserve(std::size_t(T));
  std::vector<std::pair<int, bool>> stack = {{root_, false}};
  while (!stack.empty()) {
    auto [id, expanded] = stack.back();
    stack.pop_back();
    Cluster& c = clusters_[std::size_t(id)];
    if (expanded) {
      const Cluster& a = clusters_[std::size_t(c.child[0])];
      const Cluster& b = clusters_[std::size_t(c.child[1])];
      c.first_face = a.first_face;
      c.face_count = a.face_count + b.face_count;
      post_order_.push_back(id);
      continue;
    }
    c.depth = c.parent >= 0 ? clusters_[std::size_t(c.parent)].depth + 1 : 0;
    max_depth_ = std::max(max_depth_, c.depth);
    if (c.leaf()) {
      c.first_face = int(faces_.size());
      c.face_count = 1;
      faces_.push_back(id);  // leaf id == its triangle
      post_order_.push_back(id);
      continue;
    }
    stack.push_back({id, true});
    stack.push_back({c.child[1], false});
    stack.push_back({c.child[0], false});
  }
}

void Hierarchy::build_boundaries() {
  // Boundaries, bottom-up: a parent's edges are its children's minus the pairs that cancel.
  std::vector<std::vector<std::array<int, 2>>> edges(clusters_.size());
  for (int id : post_order_) {
    const Cluster& c = clusters_[std::size_t(id)];
    auto& out = edges[std::size_t(id)];
    if (c.leaf()) {
      const auto& w = welded_triangles_[std::size_t(id)];
      for (int k = 0; k < 3; ++k) out.push_back({w[std::size_t(k)], w[std::size_t((k + 1) % 3)]});
      continue;
    }
    std::unordered_map<std::uint64_t, int> count;  // +1 for a -> b with a < b, -1 for b -> a
    for (int ch : c.child)
      for (const auto& e : edges[std::size_t(ch)]) count[edge_key(e[0], e[1])] += e[0] < e[1] ? 1 : -1;
    for (int ch : c.child)
      for (const auto& e : edges[std::size_t(ch)]) {
        int& n = count[edge_key(e[0], e[1])];
        const int sign = e[0] < e[1] ? 1 : -1;
        if (n * sign > 0) {  // this orientation is in excess: keep one copy
          out.push_back(e);
          n -= sign;
        }
      }
    // The children's lists are no longer needed once both parents' levels are built.
  }
  for (std::size_t id = 0; id < clusters_.size(); ++id) {
    Cluster& c = clusters_[id];
    c.first_edge = int(boundary_.size());
    c.edge_count = int(edges[id].size());
    boundary_.insert(boundary_.end(), edges[id].begin(), edges[id].end());
  }
}

void Hierarchy::update_geometry(const std::vector<Vec3f>& positions) {
  if (positions.size() != weld_.size()) {
    throw Error("hierarchical: " + std::to_string(positions.size()) + " vertices, the mesh had " +
                std::to_string(weld_.size()));
  }
  for (std::size_t v = 0; v < positions.size(); ++v) {
    welded_[std::size_t(weld_[v])] = positions[v].cast<double>();
  }
  std::vector<Vec3d> normal_sum(clusters_.size(), Vec3d::Zero());
  auto leaf = [&](std::size_t t) {
    const auto& w = welded_triangles_[t];
    const Vec3d &a = welded_[std::size_t(w[0])], &b = welded_[std::size_t(w[1])],
                &c = welded_[std::size_t(w[2])];
    Cluster& cl = clusters_[t];
    const Vec3d n2 = (b - a).cross(c - a);
    cl.area = 0.5 * n2.norm();
    normal_sum[t] = 0.5 * n2;
    cl.midpoint = (a + b + c) / 3;
    cl.normal = cl.area > 0 ? Vec3d(n2.normalized()) : Vec3d::UnitZ();
    cl.projected_area = cl.area;
    cl.radius = std::max({(a - cl.midpoint).norm(), (b - cl.midpoint).norm(),
                          (c - cl.midpoint).norm()});
  };
  if (post_order_.empty()) {  // during build: leaves only
    for (std::size_t t = 0; t < welded_triangles_.size(); ++t) leaf(t);
    return;
  }
  for (int id : post_order_) {
    Cluster& c = clusters_[std::size_t(id)];
    if (c.leaf()) {
      leaf(std::size_t(id));
      continue;
    }
    const Cluster& a = clusters_[std::size_t(c.child[0])];
    const Cluster& b = clusters_[std::size_t(c.child[1])];
    merged_sphere(a, b, c.midpoint, c.radius, c.area);
    normal_sum[std::size_t(id)] =
        normal_sum[std::size_t(c.child[0])] + normal_sum[std::size_t(c.child[1])];
    c.projected_area = normal_sum[std::size_t(id)].norm();
    c.normal = c.projected_area > 0 ? Vec3d(normal_sum[std::size_t(id)] / c.projected_area)
                                    : Vec3d::UnitZ();
  }
}

}  // namespace lucent::render::hierarchical
