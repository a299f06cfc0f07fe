// `NAME@T`: a mesh simplified to about T triangles (mesh_io.h), by meshoptimizer's edge collapses
// under quadric error (Garland and Heckbert's metric): a well-kept library for what is not our
// field.
#include <meshoptimizer.h>

#include <algorithm>
#include <map>
#include <string>

#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/render/mesh_io.h"

namespace lucent::render {

Mesh simplify_mesh(const Mesh& mesh, std::size_t target_triangles, const std::string& name) {
  if (target_triangles < 4) {
    throw Error("mesh '" + name + "': expected at least 4 triangles after '@', got " +
                std::to_string(target_triangles));
  }
  if (target_triangles >= mesh.triangles.size()) {
    throw Error("mesh '" + name + "': it has " + std::to_string(mesh.triangles.size()) +
                " triangles, expected fewer after '@' (" + std::to_string(target_triangles) + ")");
  }
  // Corners at one position are one vertex (a crease's copies, a scan's seams), so that the
  // simplifier sees the surface's connectivity.
  std::map<std::array<float, 3>, unsigned> index_of;
  std::vector<float> positions;
  std::vector<unsigned> remap(mesh.positions.size());
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const Vec3f& p = mesh.positions[v];
    const auto [it, inserted] =
        index_of.emplace(std::array<float, 3>{p.x(), p.y(), p.z()}, unsigned(positions.size() / 3));
    if (inserted) positions.insert(positions.end(), {p.x(), p.y(), p.z()});
    remap[v] = it->second;
  }
  std::vector<unsigned> indices;
  indices.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles)
    for (unsigned v : t) indices.push_back(remap[v]);
  std::vector<unsigned> out(indices.size());
  const std::size_t vertex_count = positions.size() / 3;
  // target_error 1: as much error as it takes to reach the count (the count is what is asked).
  out.resize(meshopt_simplify(out.data(), indices.data(), indices.size(), positions.data(),
                              vertex_count, 3 * sizeof(float), target_triangles * 3, 1.0f, 0,
                              nullptr));
  Mesh simple;
  std::vector<int> used(vertex_count, -1);
  for (std::size_t i = 0; i < out.size(); i += 3) {
    std::array<unsigned, 3> tri{};
    for (int k = 0; k < 3; ++k) {
      const unsigned v = out[i + std::size_t(k)];
      if (used[v] < 0) {
        used[v] = int(simple.positions.size());
        simple.positions.emplace_back(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
      }
      tri[std::size_t(k)] = unsigned(used[v]);
    }
    simple.triangles.push_back(tri);
  }
  if (simple.triangles.empty()) throw Error("mesh '" + name + "': nothing left after simplifying");
  // The simplifier stops early where no collapse keeps the surface's topology (a scan's tunnels,
  // thin parts): said, not hidden.
  if (double(simple.triangles.size()) > 1.1 * double(target_triangles)) {
    warn("warning: " + name + ": simplified to " + std::to_string(simple.triangles.size()) +
         " triangles, not " + std::to_string(target_triangles) +
         " (no further collapse keeps the surface)");
  }
  return simple;
}

}  // namespace lucent::render
