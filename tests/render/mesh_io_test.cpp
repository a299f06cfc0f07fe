// The PLY and OBJ readers: good files of each kind agree, and every bad file is one lucent::Error
// naming the file and what is wrong (never a crash, never an allocation the file cannot back).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "lucent/core/error.h"
#include "lucent/render/mesh_io.h"

namespace lucent::render {
namespace {

std::string seed(const std::string& name) {
  std::ifstream in(std::string(LUCENT_SOURCE_DIR) + "/fuzz/seeds/mesh/" + name, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(MeshIo, TheCubeReadsTheSameFromEveryEncoding) {
  const Mesh ascii = parse_ply(seed("cube_ascii.ply"), "cube_ascii.ply");
  const Mesh little = parse_ply(seed("cube_binary.ply"), "cube_binary.ply");
  const Mesh big = parse_ply(seed("cube_big_normals.ply"), "cube_big_normals.ply");
  const Mesh obj = parse_obj(seed("cube.obj"), "cube.obj");
  for (const Mesh* m : {&ascii, &little, &big}) {
    ASSERT_EQ(m->positions.size(), 8u);
    ASSERT_EQ(m->triangles.size(), 12u);  // six quads as fans
    for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(m->positions[i], ascii.positions[i]);
    for (std::size_t t = 0; t < 12; ++t) EXPECT_EQ(m->triangles[t], ascii.triangles[t]);
  }
  // The OBJ gives a normal at some corners: a vertex is a position with its normal (or none).
  ASSERT_EQ(obj.triangles.size(), 12u);
  ASSERT_EQ(obj.normals.size(), obj.positions.size());
  for (std::size_t t = 0; t < 12; ++t)
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(obj.positions[obj.triangles[t][std::size_t(k)]],
                ascii.positions[ascii.triangles[t][std::size_t(k)]]);
  EXPECT_TRUE(ascii.normals.empty());
  ASSERT_EQ(big.normals.size(), 8u);
  EXPECT_FLOAT_EQ(big.normals[7].x(), 0.5f);
  const Mesh scaled = finish_mesh(ascii, "cube", 100.0);
  EXPECT_NEAR((scaled.bounds_max() - scaled.bounds_min()).norm(), 100.0, 1e-4);
}

struct BadMesh {
  const char* name;
  bool ply;
  std::string bytes;
  const char* needle;
};

void PrintTo(const BadMesh& c, std::ostream* os) { *os << c.name; }

std::string truncated(const std::string& s, std::size_t drop) { return s.substr(0, s.size() - drop); }

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

class BadMeshes : public ::testing::TestWithParam<BadMesh> {};

// A cube as modellers write it: eight positions, six face normals, each corner naming its face's.
const char* kCubeWithNormals = R"(v -1 -1 -1
v 1 -1 -1
v 1 1 -1
v -1 1 -1
v -1 -1 1
v 1 -1 1
v 1 1 1
v -1 1 1
vn 0 0 -1
vn 0 0 1
vn 0 -1 0
vn 0 1 0
vn -1 0 0
vn 1 0 0
f 1//1 4//1 3//1 2//1
f 5//2 6//2 7//2 8//2
f 1//3 2//3 6//3 5//3
f 4//4 8//4 7//4 3//4
f 1//5 5//5 8//5 4//5
f 2//6 3//6 7//6 6//6
)";

// The same cube without normals.
std::string cube_without_normals() {
  std::string text;
  for (const std::string line :
       {"v -1 -1 -1", "v 1 -1 -1", "v 1 1 -1", "v -1 1 -1", "v -1 -1 1", "v 1 -1 1", "v 1 1 1",
        "v -1 1 1", "f 1 4 3 2", "f 5 6 7 8", "f 1 2 6 5", "f 4 8 7 3", "f 1 5 8 4", "f 2 3 7 6"})
    text += line + "\n";
  return text;
}

// Every corner's normal is its triangle's own: flat faces.
double worst_flatness(const Mesh& m) {
  double worst = 1;
  for (const auto& t : m.triangles) {
    const Vec3f face = (m.positions[t[1]] - m.positions[t[0]])
                           .cross(m.positions[t[2]] - m.positions[t[0]])
                           .normalized();
    for (unsigned v : t) worst = std::min(worst, double(face.dot(m.normals[v])));
  }
  return worst;
}

TEST(MeshIo, AnObjCubeKeepsItsFaceNormals) {
  const Mesh cube = finish_mesh(parse_obj(kCubeWithNormals, "cube.obj"), "cube.obj", 100.0);
  EXPECT_EQ(cube.positions.size(), 24u);  // each corner once per face that meets there
  EXPECT_EQ(cube.triangles.size(), 12u);
  EXPECT_GT(worst_flatness(cube), 0.9999);  // the file's normals, not a smooth blob
  // Even with a crease angle of 180 (smooth everywhere): the file's normals win.
  const Mesh smooth =
      finish_mesh(parse_obj(kCubeWithNormals, "cube.obj"), "cube.obj", 100.0, false, 180);
  EXPECT_GT(worst_flatness(smooth), 0.9999);
}

// NAME@T: simplified to about T triangles, still a closed surface of the asked size; bad counts
// are one-line errors naming the mesh.
TEST(MeshIo, SimplifiedMeshesKeepTheirSurface) {
  const Mesh fine = load_mesh("sphere:4", 100);
  const Mesh simple = load_mesh("sphere:4@1000", 100);
  EXPECT_EQ(simple.name, "sphere:4@1000");
  EXPECT_LE(simple.triangles.size(), 1000u);
  EXPECT_GE(simple.triangles.size(), 900u);
  EXPECT_EQ(simple.normals.size(), simple.positions.size());
  // A closed mesh: every edge shared by exactly two triangles.
  std::map<std::pair<unsigned, unsigned>, int> edges;
  for (const auto& t : simple.triangles)
    for (int k = 0; k < 3; ++k) {
      const unsigned a = t[std::size_t(k)], b = t[std::size_t((k + 1) % 3)];
      ++edges[{std::min(a, b), std::max(a, b)}];
    }
  for (const auto& [edge, count] : edges) ASSERT_EQ(count, 2);
  // Still a 100 mm sphere: every vertex within 2% of the radius of the fine one's.
  const float radius = fine.positions[0].norm();
  for (const Vec3f& p : simple.positions) EXPECT_NEAR(p.norm(), radius, 0.02 * radius);
  for (const char* bad : {"sphere:4@abc", "sphere:2@5000", "sphere@2", "nothing@100"}) {
    try {
      load_mesh(bad, 100);
      ADD_FAILURE() << bad << " loaded";
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("'" + std::string(bad).substr(0, std::string(bad).find('@'))),
                std::string::npos)
          << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

TEST(MeshIo, ACubeWithoutNormalsGetsHardEdgesAtTheCreaseAngle) {
  const Mesh hard =
      finish_mesh(parse_obj(cube_without_normals(), "cube.obj"), "cube.obj", 100.0, false, 60);
  EXPECT_EQ(hard.positions.size(), 24u);
  EXPECT_GT(worst_flatness(hard), 0.9999);
  // 180: one smooth normal per corner, between the faces' (a blob's shading).
  const Mesh smooth =
      finish_mesh(parse_obj(cube_without_normals(), "cube.obj"), "cube.obj", 100.0, false, 180);
  EXPECT_EQ(smooth.positions.size(), 8u);
  EXPECT_LT(worst_flatness(smooth), 0.8);
  // A curved surface (a band of a sphere in 24 x 24 quads, 15 degrees apart) has no edge sharper
  // than 60 degrees: nothing is split.
  Mesh ball;
  const int n = 24;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j < n; ++j) {
      const double theta = 3.14159265358979 * i / n, phi = 2 * 3.14159265358979 * j / n;
      ball.positions.emplace_back(float(std::sin(theta) * std::cos(phi)),
                                  float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)));
    }
  for (int i = 1; i < n - 1; ++i)  // not the poles' rows, whose triangles have no area
    for (int j = 0; j < n; ++j) {
      const unsigned a = unsigned(i * n + j), b = unsigned(i * n + (j + 1) % n),
                     c = unsigned((i + 1) * n + j), d = unsigned((i + 1) * n + (j + 1) % n);
      ball.triangles.push_back({a, c, d});
      ball.triangles.push_back({a, d, b});
    }
  Mesh creased = ball;
  EXPECT_EQ(crease_normals(creased, 60), 0u);
  EXPECT_THROW(
      finish_mesh(parse_obj(cube_without_normals(), "cube.obj"), "cube.obj", 100.0, false, 200),
      Error);
}

TEST_P(BadMeshes, AreOneLineErrorsNamingTheProblem) {
  const BadMesh& c = GetParam();
  const std::string source = c.ply ? "bad.ply" : "bad.obj";
  try {
    Mesh m = c.ply ? parse_ply(c.bytes, source) : parse_obj(c.bytes, source);
    (void)finish_mesh(std::move(m), source, 100.0);
    FAIL() << c.name << ": accepted";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(c.needle), std::string::npos) << c.name << ": " << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

std::vector<BadMesh> bad_meshes() {
  const std::string a = seed("cube_ascii.ply"), b = seed("cube_binary.ply"), o = seed("cube.obj");
  return {
      {"binary_one_byte_short", true, truncated(b, 1), "ends early"},
      {"binary_header_only", true, b.substr(0, b.find("end_header") + 11), "more than"},
      {"ascii_short", true, truncated(a, 10), "ends early"},
      {"huge_vertex_count", true, replaced(b, "element vertex 8", "element vertex 2000000000"),
       "more than"},
      {"huge_face_count", true, replaced(b, "element face 6", "element face 4000000000"),
       "more than"},
      {"not_ply", true, "solid cube\nfacet normal 0 0 1\n", "not a PLY file"},
      {"empty", true, "", "not a PLY file"},
      {"no_end_header", true, "ply\nformat ascii 1.0\nelement vertex 0\n", "end_header"},
      {"no_format", true, "ply\nelement vertex 0\nend_header\n", "format"},
      {"bad_format", true, replaced(a, "ascii", "utf8"), "unknown PLY format"},
      {"bad_type", true, replaced(a, "property float x", "property quad x"),
       "unknown property type"},
      {"no_z", true, replaced(a, "property float z", "property float w"), "x, y and z"},
      {"nan_vertex", true, replaced(a, "\n0 0 0\n", "\nnan 0 0\n"), "not finite"},
      {"inf_vertex", true, replaced(a, "\n0 0 0\n", "\n1e999 0 0\n"), "vertex 0"},
      {"index_out_of_range", true, replaced(a, "4 0 1 3 2", "4 0 1 3 8"), "out of range"},
      // Found by fuzz_mesh_loader: an index beyond every integer type (UBSan: float-cast-overflow).
      {"index_beyond_long_long", true,
       replaced(a, "4 2 3 7 6", "4 2 3 7 6222222222222222222222222222"), "out of range"},
      {"negative_index", true, replaced(a, "4 0 1 3 2", "4 0 1 3 -1"), "out of range"},
      {"fraction_index", true, replaced(a, "4 0 1 3 2", "4 0 1 3 2.5"), "integer"},
      {"word_in_body", true, replaced(a, "\n1 1 1\n", "\n1 one 1\n"), "expected a number"},
      {"list_too_long", true, replaced(a, "4 0 1 3 2", "200 0 1 3 2"), "list length"},
      {"float_indices", true, replaced(a, "list uchar int", "list uchar float"), "integer type"},
      {"property_first", true, "ply\nformat ascii 1.0\nproperty float x\nend_header\n",
       "before any element"},
      {"faces_no_triangles", true,
       replaced(replaced(a, "element face 6", "element face 0"), "4 0 1 3 2", ""), "no triangles"},
      {"all_vertices_coincide", true,
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty "
       "float z\n"
       "element face 1\nproperty list uchar int vertex_indices\nend_header\n1 1 1\n1 1 1\n1 1 1\n3 "
       "0 1 2\n",
       "coincide"},
      {"obj_nan", false, replaced(o, "v 0 0 0", "v nan 0 0"), "not finite"},
      {"obj_index_zero", false, replaced(o, "f 1/1/1", "f 0/1/1"), "vertex index"},
      {"obj_index_high", false, replaced(o, "f 1/1/1", "f 99/1/1"), "out of range"},
      {"obj_negative_too_far", false, replaced(o, "-7\n", "-70\n"), "out of range"},
      {"obj_short_vertex", false, replaced(o, "v 0 0 1", "v 0 0"), "expected 'v x y z'"},
      {"obj_word", false, replaced(o, "v 0 0 1", "v 0 zero 1"), "expected a number"},
      {"obj_two_vertex_face", false, o + "f 1 2\n", "at least 3"},
      {"obj_nothing", false, "# only a comment\n", "no triangles"},
      {"obj_normal_index_high", false, replaced(o, "4//1", "4//7"),
       "normal index 7 is out of range (1 normals so far)"},
      {"obj_nan_normal", false, replaced(o, "vn 0 0 1", "vn 0 nan 1"), "not finite"},
      {"obj_short_normal", false, replaced(o, "vn 0 0 1", "vn 0 1"), "expected 'vn x y z'"},
  };
}

INSTANTIATE_TEST_SUITE_P(Cases, BadMeshes, ::testing::ValuesIn(bad_meshes()),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace lucent::render
