// The per-cluster projection maps of irradiance (irradiance_cache.h).
#include "irradiance_cache.h"

#include <atomic>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <numbers>
#include <queue>

namespace lucent::render::detail {

struct IrradianceCache::Vertex {
  Vec3f x = Vec3f::Zero(), n = Vec3f::UnitZ(), g = Vec3f::UnitZ();
  float quality = -std::numeric_limits<float>::infinity();  // min barycentric; -inf: unassigned
  std::uint64_t key = 0;
  std::once_flag once;
  Rgb E{0, 0, 0};
  Vec3f w = Vec3f::Zero();
};

struct IrradianceCache::Cluster {
  Vec3f origin = Vec3f::Zero(), e1 = Vec3f::UnitX(), e2 = Vec3f::UnitY();
  float u0 = 0, v0 = 0, texel = 1;
  int nx = 0, ny = 0;
  std::unique_ptr<Vertex[]> vertices;
  Vertex& at(int i, int j) const { return vertices[std::size_t(j) * std::size_t(nx) + std::size_t(i)]; }
};


IrradianceCache::IrradianceCache(const Mesh& mesh, const std::vector<Light>& lights,
                                 const RayScene* rays, double eta,
                                 const IrradianceCacheOptions& options)
    : mesh_(mesh), rays_(rays), eta_(eta), options_(options) {
  for (const Light& l : lights) {
    if (l.type == LightType::kArea) lights_.push_back(l);
  }
  const float size = (mesh.bounds_max() - mesh.bounds_min()).norm();
  eps_ = 1e-4f * std::max(mesh.bounding_radius(), 1e-6f);
  const float texel = options.texel_mm > 0 ? float(options.texel_mm)
                                           : std::max(mesh.bounding_radius(), 1e-6f) / 64.0f;
  const std::size_t T = mesh.triangles.size();
  face_cluster_.assign(T, -1);

  // Welded vertices and the faces around each.
  const double tolerance = std::max(1e-5 * double(size), 1e-12);
  std::map<std::array<long long, 3>, int> weld;
  std::vector<int> welded(mesh.positions.size());
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    std::array<long long, 3> k;
    for (int c = 0; c < 3; ++c) k[std::size_t(c)] = std::llround(mesh.positions[i][c] / tolerance);
    welded[i] = weld.emplace(k, int(weld.size())).first->second;
  }
  std::vector<std::vector<std::size_t>> around(weld.size());
  std::vector<Vec3f> normal(T, Vec3f::Zero());
  std::vector<float> area(T, 0.0f);
  for (std::size_t t = 0; t < T; ++t) {
    const auto& tri = mesh.triangles[t];
    const Vec3f c = (mesh.positions[tri[1]] - mesh.positions[tri[0]])
                        .cross(mesh.positions[tri[2]] - mesh.positions[tri[0]]);
    area[t] = 0.5f * c.norm();
    if (area[t] > 0) normal[t] = c.normalized();
    for (unsigned v : tri) around[std::size_t(welded[v])].push_back(t);
  }

  // Clusters grown over shared welded vertices within the normal cone of their first face.
  const float cos_max = float(std::cos(options.max_normal_angle_deg * std::numbers::pi / 180));
  std::vector<std::vector<std::size_t>> members;
  for (std::size_t seed = 0; seed < T; ++seed) {
    if (face_cluster_[seed] >= 0 || !(area[seed] > 0)) continue;
    const int id = int(members.size());
    members.emplace_back();
    std::queue<std::size_t> open;
    open.push(seed);
    face_cluster_[seed] = id;
    while (!open.empty()) {
      const std::size_t t = open.front();
      open.pop();
      members.back().push_back(t);
      for (unsigned v : mesh.triangles[t]) {
        for (std::size_t u : around[std::size_t(welded[v])]) {
          if (face_cluster_[u] >= 0 || !(area[u] > 0) || normal[u].dot(normal[seed]) < cos_max)
            continue;
          face_cluster_[u] = id;
          open.push(u);
        }
      }
    }
  }

  // One projection per cluster; grid vertices assigned to the face that contains them (or the
  // least-extrapolated nearby face, for padding).
  clusters_.resize(members.size());
  std::uint64_t key = 0x1234567ull;
  for (std::size_t c = 0; c < members.size(); ++c) {
    Cluster& cl = clusters_[c];
    Vec3f N = Vec3f::Zero();
    for (std::size_t t : members[c]) N += area[t] * normal[t];
    N = N.norm() > 0 ? Vec3f(N.normalized()) : normal[members[c].front()];
    cl.e1 = N.unitOrthogonal();
    cl.e2 = N.cross(cl.e1);
    cl.origin = mesh.positions[mesh.triangles[members[c].front()][0]];
    float umin = std::numeric_limits<float>::infinity(), vmin = umin, umax = -umin, vmax = -umin;
    for (std::size_t t : members[c]) {
      for (unsigned v : mesh.triangles[t]) {
        const Vec3f d = mesh.positions[v] - cl.origin;
        umin = std::min(umin, cl.e1.dot(d)), umax = std::max(umax, cl.e1.dot(d));
        vmin = std::min(vmin, cl.e2.dot(d)), vmax = std::max(vmax, cl.e2.dot(d));
      }
    }
    // A guard on memory: at most 4M grid vertices per cluster (the texel grows for huge ones).
    cl.texel = texel;
    while ((double((umax - umin) / cl.texel) + 3) * (double((vmax - vmin) / cl.texel) + 3) > 4e6)
      cl.texel *= 2;
    cl.u0 = umin - cl.texel;
    cl.v0 = vmin - cl.texel;
    cl.nx = int(std::floor((umax - umin) / cl.texel)) + 3;
    cl.ny = int(std::floor((vmax - vmin) / cl.texel)) + 3;
    cl.vertices = std::make_unique<Vertex[]>(std::size_t(cl.nx) * std::size_t(cl.ny));
    for (std::size_t t : members[c]) {
      const auto& tri = mesh.triangles[t];
      Eigen::Vector2f p[3];
      for (int k = 0; k < 3; ++k) {
        const Vec3f d = mesh.positions[tri[std::size_t(k)]] - cl.origin;
        p[k] = Eigen::Vector2f(cl.e1.dot(d), cl.e2.dot(d));
      }
      const float det = (p[1] - p[0]).x() * (p[2] - p[0]).y() - (p[1] - p[0]).y() * (p[2] - p[0]).x();
      if (!(std::abs(det) > 0)) continue;
      const Eigen::Vector2f lo = p[0].cwiseMin(p[1]).cwiseMin(p[2]),
                            hi = p[0].cwiseMax(p[1]).cwiseMax(p[2]);
      const int i0 = std::max(0, int(std::floor((lo.x() - cl.u0) / cl.texel)) - 1);
      const int i1 = std::min(cl.nx - 1, int(std::ceil((hi.x() - cl.u0) / cl.texel)) + 1);
      const int j0 = std::max(0, int(std::floor((lo.y() - cl.v0) / cl.texel)) - 1);
      const int j1 = std::min(cl.ny - 1, int(std::ceil((hi.y() - cl.v0) / cl.texel)) + 1);
      for (int j = j0; j <= j1; ++j) {
        for (int i = i0; i <= i1; ++i) {
          const Eigen::Vector2f q(cl.u0 + i * cl.texel, cl.v0 + j * cl.texel);
          const Eigen::Vector2f a = p[1] - p[0], b = p[2] - p[0], r = q - p[0];
          const float l1 = (r.x() * b.y() - r.y() * b.x()) / det;
          const float l2 = (a.x() * r.y() - a.y() * r.x()) / det;
          const float l0 = 1 - l1 - l2;
          const float quality = std::min({l0, l1, l2});
          Vertex& v = cl.at(i, j);
          if (!(quality > v.quality)) continue;
          v.quality = quality;
          v.x = l0 * mesh.positions[tri[0]] + l1 * mesh.positions[tri[1]] + l2 * mesh.positions[tri[2]];
          // The normal from the barycentrics clamped into the face (padding stays on its plane).
          const float c0 = std::max(l0, 0.0f), c1 = std::max(l1, 0.0f), c2 = std::max(l2, 0.0f);
          const Vec3f n = c0 * mesh.normals[tri[0]] + c1 * mesh.normals[tri[1]] + c2 * mesh.normals[tri[2]];
          v.n = n.norm() > 0 ? Vec3f(n.normalized()) : normal[t];
          v.g = normal[t];
        }
      }
    }
    for (std::size_t k = 0; k < std::size_t(cl.nx) * std::size_t(cl.ny); ++k)
      cl.vertices[k].key = mix(key + k);
    key = mix(key ^ (c + 1));
  }
}

IrradianceCache::~IrradianceCache() = default;

void IrradianceCache::evaluate(Vertex& v) const {
  AreaLightSampling sampling;
  sampling.samples = options_.shadow_samples;
  sampling.shadows = options_.shadows;
  sampling.coat = options_.coat;
  Vec3f w = Vec3f::Zero();
  for (std::size_t l = 0; l < lights_.size(); ++l) {
    const AreaIrradiance a =
        area_light_irradiance(lights_[l], v.x, v.n, v.g, rays_, eps_, eta_, sampling, mix(v.key + l));
    for (int c = 0; c < 3; ++c) v.E[std::size_t(c)] += a.transmitted * lights_[l].radiance[c];
    w += float(std::max(a.transmitted, 0.0) * lights_[l].radiance.mean()) * a.w;
  }
  v.w = w.norm() > 0 ? Vec3f(w.normalized()) : Vec3f::Zero();
}

IrradianceCache::Rgb IrradianceCache::lookup(std::size_t face, const Vec3f& x, Vec3f* w) const {
  const int id = face < face_cluster_.size() ? face_cluster_[face] : -1;
  if (id < 0) return direct(face, x, w);
  const Cluster& cl = clusters_[std::size_t(id)];
  const Vec3f d = x - cl.origin;
  const float fu = (cl.e1.dot(d) - cl.u0) / cl.texel, fv = (cl.e2.dot(d) - cl.v0) / cl.texel;
  const int i = std::clamp(int(std::floor(fu)), 0, cl.nx - 2);
  const int j = std::clamp(int(std::floor(fv)), 0, cl.ny - 2);
  const float s = std::clamp(fu - i, 0.0f, 1.0f), t = std::clamp(fv - j, 0.0f, 1.0f);
  Rgb E{0, 0, 0};
  Vec3f mean_w = Vec3f::Zero();
  const std::array<std::pair<Vertex*, float>, 4> corners = {
      std::pair{&cl.at(i, j), (1 - s) * (1 - t)}, std::pair{&cl.at(i + 1, j), s * (1 - t)},
      std::pair{&cl.at(i, j + 1), (1 - s) * t}, std::pair{&cl.at(i + 1, j + 1), s * t}};
  for (const auto& [v, weight] : corners) {
    if (!std::isfinite(v->quality)) return direct(face, x, w);  // not reached by any face
    std::call_once(v->once, [&] {
      evaluate(*v);
      ++evaluated_;
    });
    for (int c = 0; c < 3; ++c) E[std::size_t(c)] += weight * v->E[std::size_t(c)];
    mean_w += weight * v->w;
  }
  if (w) *w = mean_w.norm() > 0 ? Vec3f(mean_w.normalized()) : Vec3f::Zero();
  return E;
}

IrradianceCache::Rgb IrradianceCache::direct(std::size_t face, const Vec3f& x, Vec3f* w) const {
  Vertex v;
  v.x = x;
  const auto& tri = mesh_.triangles[face];
  const Vec3f g = (mesh_.positions[tri[1]] - mesh_.positions[tri[0]])
                      .cross(mesh_.positions[tri[2]] - mesh_.positions[tri[0]]);
  v.g = g.norm() > 0 ? Vec3f(g.normalized()) : Vec3f::UnitZ();
  // The shading normal at x: barycentric interpolation of the vertex normals.
  const Vec3f a = mesh_.positions[tri[0]], b = mesh_.positions[tri[1]], c = mesh_.positions[tri[2]];
  const float A = g.norm();
  const float l1 = A > 0 ? (x - a).cross(c - a).dot(v.g) / A : 0;
  const float l2 = A > 0 ? (b - a).cross(x - a).dot(v.g) / A : 0;
  const float l0 = 1 - l1 - l2;
  const Vec3f n = std::max(l0, 0.0f) * mesh_.normals[tri[0]] + std::max(l1, 0.0f) * mesh_.normals[tri[1]] +
                  std::max(l2, 0.0f) * mesh_.normals[tri[2]];
  v.n = n.norm() > 0 ? Vec3f(n.normalized()) : v.g;
  v.key = mix(0xD1EC7ull ^ (std::uint64_t(face) << 20) ^ std::uint64_t(std::abs(x.x() * 1e3f)));
  evaluate(v);
  if (w) *w = v.w;
  return v.E;
}

IrradianceCacheStats IrradianceCache::stats() const {
  IrradianceCacheStats s;
  s.clusters = clusters_.size();
  for (const Cluster& c : clusters_) {
    for (std::size_t k = 0; k < std::size_t(c.nx) * std::size_t(c.ny); ++k)
      s.grid_vertices += std::isfinite(c.vertices[k].quality) ? 1 : 0;
  }
  s.evaluated = evaluated_.load();
  s.texel_mm = clusters_.empty() ? 0.0 : clusters_.front().texel;
  return s;
}

}  // namespace lucent::render::detail
