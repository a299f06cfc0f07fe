// The PLY and OBJ readers: good files of each kind agree, and every bad file is one lucent::Error
// naming the file and what is wrong (never a crash, never an allocation the file cannot back).
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
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
  for (const Mesh* m : {&ascii, &little, &big, &obj}) {
    ASSERT_EQ(m->positions.size(), 8u);
    ASSERT_EQ(m->triangles.size(), 12u);  // six quads as fans
    for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(m->positions[i], ascii.positions[i]);
    for (std::size_t t = 0; t < 12; ++t) EXPECT_EQ(m->triangles[t], ascii.triangles[t]);
  }
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
      {"huge_vertex_count", true, replaced(b, "element vertex 8", "element vertex 2000000000"), "more than"},
      {"huge_face_count", true, replaced(b, "element face 6", "element face 4000000000"), "more than"},
      {"not_ply", true, "solid cube\nfacet normal 0 0 1\n", "not a PLY file"},
      {"empty", true, "", "not a PLY file"},
      {"no_end_header", true, "ply\nformat ascii 1.0\nelement vertex 0\n", "end_header"},
      {"no_format", true, "ply\nelement vertex 0\nend_header\n", "format"},
      {"bad_format", true, replaced(a, "ascii", "utf8"), "unknown PLY format"},
      {"bad_type", true, replaced(a, "property float x", "property quad x"), "unknown property type"},
      {"no_z", true, replaced(a, "property float z", "property float w"), "x, y and z"},
      {"nan_vertex", true, replaced(a, "\n0 0 0\n", "\nnan 0 0\n"), "not finite"},
      {"inf_vertex", true, replaced(a, "\n0 0 0\n", "\n1e999 0 0\n"), "vertex 0"},
      {"index_out_of_range", true, replaced(a, "4 0 1 3 2", "4 0 1 3 8"), "out of range"},
      // Found by fuzz_mesh_loader: an index beyond every integer type (UBSan: float-cast-overflow).
      {"index_beyond_long_long", true, replaced(a, "4 2 3 7 6", "4 2 3 7 6222222222222222222222222222"),
       "out of range"},
      {"negative_index", true, replaced(a, "4 0 1 3 2", "4 0 1 3 -1"), "out of range"},
      {"fraction_index", true, replaced(a, "4 0 1 3 2", "4 0 1 3 2.5"), "integer"},
      {"word_in_body", true, replaced(a, "\n1 1 1\n", "\n1 one 1\n"), "expected a number"},
      {"list_too_long", true, replaced(a, "4 0 1 3 2", "200 0 1 3 2"), "list length"},
      {"float_indices", true, replaced(a, "list uchar int", "list uchar float"), "integer type"},
      {"property_first", true, "ply\nformat ascii 1.0\nproperty float x\nend_header\n", "before any element"},
      {"faces_no_triangles", true, replaced(replaced(a, "element face 6", "element face 0"), "4 0 1 3 2", ""), "no triangles"},
      {"all_vertices_coincide", true,
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
       "element face 1\nproperty list uchar int vertex_indices\nend_header\n1 1 1\n1 1 1\n1 1 1\n3 0 1 2\n",
       "coincide"},
      {"obj_nan", false, replaced(o, "v 0 0 0", "v nan 0 0"), "not finite"},
      {"obj_index_zero", false, replaced(o, "f 1/1/1", "f 0/1/1"), "vertex index"},
      {"obj_index_high", false, replaced(o, "f 1/1/1", "f 99/1/1"), "out of range"},
      {"obj_negative_too_far", false, replaced(o, "-7\n", "-70\n"), "out of range"},
      {"obj_short_vertex", false, replaced(o, "v 0 0 1", "v 0 0"), "expected 'v x y z'"},
      {"obj_word", false, replaced(o, "v 0 0 1", "v 0 zero 1"), "expected a number"},
      {"obj_two_vertex_face", false, o + "f 1 2\n", "at least 3"},
      {"obj_nothing", false, "# only a comment\n", "no triangles"},
  };
}

INSTANTIATE_TEST_SUITE_P(Cases, BadMeshes, ::testing::ValuesIn(bad_meshes()),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace lucent::render
