// parse_ply and parse_obj (see mesh_io.h), and the Mesh measures (scene.h).
#include "lucent/render/mesh_io.h"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <vector>

#include "lucent/core/error.h"

namespace lucent::render {
namespace {

enum class Format { kAscii, kLittle, kBig };

enum class Type { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

std::optional<Type> parse_type(std::string_view name) {
  if (name == "char" || name == "int8") return Type::kInt8;
  if (name == "uchar" || name == "uint8") return Type::kUint8;
  if (name == "short" || name == "int16") return Type::kInt16;
  if (name == "ushort" || name == "uint16") return Type::kUint16;
  if (name == "int" || name == "int32") return Type::kInt32;
  if (name == "uint" || name == "uint32") return Type::kUint32;
  if (name == "float" || name == "float32") return Type::kFloat32;
  if (name == "double" || name == "float64") return Type::kFloat64;
  return std::nullopt;
}

std::size_t size_of(Type t) {
  switch (t) {
    case Type::kInt8:
    case Type::kUint8:
      return 1;
    case Type::kInt16:
    case Type::kUint16:
      return 2;
    case Type::kInt32:
    case Type::kUint32:
    case Type::kFloat32:
      return 4;
    case Type::kFloat64:
      return 8;
  }
  return 1;
}

bool is_integer(Type t) { return t != Type::kFloat32 && t != Type::kFloat64; }

struct Property {
  std::string name;
  Type type = Type::kFloat32;
  bool list = false;
  Type count_type = Type::kUint8;
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

// Reads values of the body one at a time, ascii or binary, never past the end.
class BodyReader {
 public:
  BodyReader(std::string_view body, Format format, const std::string& source)
      : body_(body), format_(format), source_(source) {}

  std::size_t left() const { return body_.size() - pos_; }

  double read(Type type, const std::string& where) {
    if (format_ == Format::kAscii) return read_ascii(type, where);
    const std::size_t n = size_of(type);
    if (left() < n) {
      throw Error(source_ + ": " + where + ": the file ends early (truncated after " +
                  std::to_string(pos_) + " bytes of data)");
    }
    unsigned char b[8];
    std::memcpy(b, body_.data() + pos_, n);
    pos_ += n;
    const bool swap = (format_ == Format::kBig) == (std::endian::native == std::endian::little);
    if (swap) std::reverse(b, b + n);
    switch (type) {
      case Type::kInt8: return static_cast<std::int8_t>(b[0]);
      case Type::kUint8: return b[0];
      case Type::kInt16: { std::int16_t v; std::memcpy(&v, b, 2); return v; }
      case Type::kUint16: { std::uint16_t v; std::memcpy(&v, b, 2); return v; }
      case Type::kInt32: { std::int32_t v; std::memcpy(&v, b, 4); return v; }
      case Type::kUint32: { std::uint32_t v; std::memcpy(&v, b, 4); return v; }
      case Type::kFloat32: { float v; std::memcpy(&v, b, 4); return v; }
      case Type::kFloat64: { double v; std::memcpy(&v, b, 8); return v; }
    }
    return 0;
  }

  // A list property's length, checked against what is left (each item takes at least a byte).
  std::uint64_t list_length(const Property& p, const std::string& where) {
    const double n = read(p.count_type, where);
    if (!(n >= 0) || n > double(left())) {
      throw Error(source_ + ": " + where + ": list length " + std::to_string(n) +
                  " is out of range");
    }
    return static_cast<std::uint64_t>(n);
  }

  // Reads past one property's value (a scalar, or a whole list).
  void skip(const Property& p, const std::string& where) {
    if (!p.list) {
      read(p.type, where);
      return;
    }
    for (std::uint64_t j = 0, n = list_length(p, where); j < n; ++j) read(p.type, where);
  }

  // The fewest bytes one item of `e` can take: checks a header's count before anything is
  // allocated for it.
  std::size_t min_item_bytes(const Element& e) const {
    std::size_t bytes = 0;
    for (const Property& p : e.properties) {
      if (format_ == Format::kAscii) bytes += 2;  // a digit and a separator
      else bytes += p.list ? size_of(p.count_type) : size_of(p.type);
    }
    return std::max<std::size_t>(bytes, 1);
  }

 private:
  double read_ascii(Type type, const std::string& where) {
    while (pos_ < body_.size() && std::isspace(static_cast<unsigned char>(body_[pos_]))) ++pos_;
    std::size_t end = pos_;
    while (end < body_.size() && !std::isspace(static_cast<unsigned char>(body_[end]))) ++end;
    if (end == pos_) {
      throw Error(source_ + ": " + where + ": the file ends early (fewer values than the header "
                  "declares)");
    }
    const char* first = body_.data() + pos_;
    const char* last = body_.data() + end;
    double v = 0;
    const auto [ptr, ec] = std::from_chars(first, last, v);
    if (ec != std::errc() || ptr != last || (is_integer(type) && v != std::floor(v))) {
      throw Error(source_ + ": " + where + ": expected " +
                  (is_integer(type) ? "an integer" : "a number") + ", got '" +
                  std::string(first, std::min<std::size_t>(last - first, 32)) + "'");
    }
    pos_ = end;
    return v;
  }

  std::string_view body_;
  std::size_t pos_ = 0;
  Format format_;
  const std::string& source_;
};

unsigned vertex_index(double v, std::size_t vertices, const std::string& source,
                      const std::string& where) {
  if (!(v >= 0) || v >= static_cast<double>(vertices)) {
    char text[32];
    std::snprintf(text, sizeof text, "%.15g", v);  // any double: no cast of an out-of-range value
    throw Error(source + ": " + where + ": vertex index " + text +
                " is out of range (the file has " + std::to_string(vertices) + " vertices)");
  }
  return static_cast<unsigned>(v);
}

void check_finite(const Vec3f& p, const std::string& source, const std::string& where) {
  if (!p.allFinite()) throw Error(source + ": " + where + ": a coordinate is not finite");
}

}  // namespace

Vec3f Mesh::bounds_min() const {
  Vec3f lo = Vec3f::Constant(std::numeric_limits<float>::infinity());
  for (const Vec3f& p : positions) lo = lo.cwiseMin(p);
  return positions.empty() ? Vec3f::Zero() : lo;
}

Vec3f Mesh::bounds_max() const {
  Vec3f hi = Vec3f::Constant(-std::numeric_limits<float>::infinity());
  for (const Vec3f& p : positions) hi = hi.cwiseMax(p);
  return positions.empty() ? Vec3f::Zero() : hi;
}

Vec3f Mesh::centre() const {
  return 0.5f * (bounds_min() + bounds_max());
}

float Mesh::bounding_radius() const {
  const Vec3f c = centre();
  float r2 = 0;
  for (const Vec3f& p : positions) r2 = std::max(r2, (p - c).squaredNorm());
  return std::sqrt(r2);
}

double Mesh::surface_area() const {
  double area = 0;
  for (const auto& t : triangles) {
    const Eigen::Vector3d a = positions[t[0]].cast<double>(), b = positions[t[1]].cast<double>(),
                          c = positions[t[2]].cast<double>();
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

namespace {

// A PLY header: the format, the elements with their properties, and where the body starts.
struct PlyHeader {
  Format format = Format::kAscii;
  std::vector<Element> elements;
  std::size_t body_offset = 0;
};

PlyHeader parse_ply_header(std::string_view bytes, const std::string& source) {
  // Header: lines up to "end_header".
  std::size_t pos = 0;
  auto next_line = [&]() -> std::optional<std::string_view> {
    if (pos >= bytes.size()) return std::nullopt;
    const std::size_t nl = bytes.find('\n', pos);
    const std::size_t end = nl == std::string_view::npos ? bytes.size() : nl;
    std::string_view line = bytes.substr(pos, end - pos);
    pos = nl == std::string_view::npos ? bytes.size() : nl + 1;
    return line;
  };
  const auto magic = next_line();
  if (!magic || words(*magic) != std::vector<std::string_view>{"ply"}) {
    throw Error(source + ": not a PLY file (it must start with the line 'ply')");
  }
  std::optional<Format> format;
  std::vector<Element> elements;
  int line_number = 1;
  for (;;) {
    const auto line = next_line();
    ++line_number;
    const std::string where = "header line " + std::to_string(line_number);
    if (!line) throw Error(source + ": the PLY header has no end_header line");
    const std::vector<std::string_view> w = words(*line);
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") break;
    if (w[0] == "format") {
      if (w.size() != 3 || w[2] != "1.0") throw Error(source + ": " + where + ": expected 'format <type> 1.0'");
      if (w[1] == "ascii") format = Format::kAscii;
      else if (w[1] == "binary_little_endian") format = Format::kLittle;
      else if (w[1] == "binary_big_endian") format = Format::kBig;
      else throw Error(source + ": " + where + ": unknown PLY format '" + std::string(w[1]) + "'");
    } else if (w[0] == "element") {
      std::uint64_t count = 0;
      if (w.size() != 3 ||
          std::from_chars(w[2].data(), w[2].data() + w[2].size(), count).ptr !=
              w[2].data() + w[2].size()) {
        throw Error(source + ": " + where + ": expected 'element <name> <count>'");
      }
      elements.push_back({std::string(w[1]), count, {}});
    } else if (w[0] == "property") {
      if (elements.empty()) throw Error(source + ": " + where + ": a property before any element");
      Property p;
      if (w.size() == 5 && w[1] == "list") {
        const auto ct = parse_type(w[2]), it = parse_type(w[3]);
        if (!ct || !it || !is_integer(*ct))
          throw Error(source + ": " + where + ": expected 'property list <integer type> <type> <name>'");
        p = {std::string(w[4]), *it, true, *ct};
      } else if (w.size() == 3) {
        const auto t = parse_type(w[1]);
        if (!t) throw Error(source + ": " + where + ": unknown property type '" + std::string(w[1]) + "'");
        p = {std::string(w[2]), *t, false, Type::kUint8};
      } else {
        throw Error(source + ": " + where + ": expected 'property <type> <name>'");
      }
      elements.back().properties.push_back(p);
    } else {
      throw Error(source + ": " + where + ": unexpected '" + std::string(w[0]) + "' in the PLY header");
    }
  }
  if (!format) throw Error(source + ": the PLY header has no format line");
  return {*format, std::move(elements), pos};
}

// The vertex element: positions (finite) and, where it has nx, ny and nz, normals.
void read_ply_vertices(BodyReader& body, const Element& e, Mesh& mesh, const std::string& source) {
  int x = -1, y = -1, z = -1, nx = -1, ny = -1, nz = -1;
  for (std::size_t i = 0; i < e.properties.size(); ++i) {
    const std::string& n = e.properties[i].name;
    if (e.properties[i].list) continue;
    if (n == "x") x = int(i);
    if (n == "y") y = int(i);
    if (n == "z") z = int(i);
    if (n == "nx") nx = int(i);
    if (n == "ny") ny = int(i);
    if (n == "nz") nz = int(i);
  }
  if (x < 0 || y < 0 || z < 0)
    throw Error(source + ": element vertex: expected properties x, y and z");
  const bool normals = nx >= 0 && ny >= 0 && nz >= 0;
  mesh.positions.reserve(e.count);
  if (normals) mesh.normals.reserve(e.count);
  std::vector<double> values(e.properties.size());
  for (std::uint64_t k = 0; k < e.count; ++k) {
    const std::string where = "vertex " + std::to_string(k);
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
      const Property& p = e.properties[i];
      if (p.list)
        body.skip(p, where);
      else
        values[i] = body.read(p.type, where);
    }
    const Vec3f position(static_cast<float>(values[x]), static_cast<float>(values[y]),
                         static_cast<float>(values[z]));
    check_finite(position, source, where);
    mesh.positions.push_back(position);
    if (normals) mesh.normals.emplace_back(float(values[nx]), float(values[ny]), float(values[nz]));
  }
}

// The face element: each polygon's vertex_indices as a fan of triangles.
void read_ply_faces(BodyReader& body, const Element& e, Mesh& mesh, const std::string& source) {
  int indices = -1;
  for (std::size_t i = 0; i < e.properties.size(); ++i) {
    const Property& p = e.properties[i];
    if (p.list && (p.name == "vertex_indices" || p.name == "vertex_index")) indices = int(i);
  }
  if (indices < 0) throw Error(source + ": element face: expected a list property vertex_indices");
  if (!is_integer(e.properties[indices].type))
    throw Error(source + ": element face: vertex_indices must have an integer type");
  std::vector<unsigned> polygon;
  for (std::uint64_t k = 0; k < e.count; ++k) {
    const std::string where = "face " + std::to_string(k);
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
      const Property& p = e.properties[i];
      if (int(i) != indices) {
        body.skip(p, where);
        continue;
      }
      polygon.clear();
      for (std::uint64_t j = 0, n = body.list_length(p, where); j < n; ++j) {
        polygon.push_back(
            vertex_index(body.read(p.type, where), mesh.positions.size(), source, where));
      }
      for (std::size_t j = 2; j < polygon.size(); ++j)  // a fan; points and lines add nothing
        mesh.triangles.push_back({polygon[0], polygon[j - 1], polygon[j]});
    }
  }
}

}  // namespace

Mesh parse_ply(std::string_view bytes, const std::string& source) {
  const PlyHeader header = parse_ply_header(bytes, source);
  BodyReader body(bytes.substr(header.body_offset), header.format, source);
  Mesh mesh;
  bool have_vertices = false;
  for (const Element& e : header.elements) {
    if (e.count > body.left() / body.min_item_bytes(e)) {
      throw Error(source + ": element " + e.name + ": the header declares " +
                  std::to_string(e.count) + " items, more than the file's " +
                  std::to_string(body.left()) + " bytes of data can hold");
    }
    if (e.name == "vertex") {
      if (have_vertices) throw Error(source + ": more than one vertex element");
      have_vertices = true;
      read_ply_vertices(body, e, mesh, source);
    } else if (e.name == "face") {
      if (!have_vertices) throw Error(source + ": element face comes before element vertex");
      read_ply_faces(body, e, mesh, source);
    } else {
      for (std::uint64_t k = 0; k < e.count; ++k) {
        const std::string where = e.name + " " + std::to_string(k);
        for (const Property& p : e.properties) body.skip(p, where);
      }
    }
  }
  if (!have_vertices) throw Error(source + ": the PLY file has no vertex element");
  for (const Vec3f& n : mesh.normals) {
    if (!n.allFinite()) {  // unusable normals: load_mesh computes them all
      mesh.normals.clear();
      break;
    }
  }
  return mesh;
}

namespace {

// One `v`/`vn` statement's three numbers.
Vec3f obj_triple(const std::vector<std::string_view>& w, const std::string& source,
                 const std::string& where, const char* statement) {
  if (w.size() < 4) throw Error(source + ": " + where + ": expected '" + statement + " x y z'");
  float c[3];
  for (int i = 0; i < 3; ++i) {
    const auto [ptr, ec] =
        std::from_chars(w[1 + i].data(), w[1 + i].data() + w[1 + i].size(), c[i]);
    if (ec != std::errc() || ptr != w[1 + i].data() + w[1 + i].size())
      throw Error(source + ": " + where + ": expected a number, got '" +
                  std::string(w[1 + i].substr(0, 32)) + "'");
  }
  const Vec3f p(c[0], c[1], c[2]);
  check_finite(p, source, where);
  return p;
}

// An index of a face corner (1-based, or negative from the latest), checked against `count`.
unsigned obj_index(std::string_view ref, std::size_t count, const std::string& source,
                   const std::string& where, std::string_view corner, const char* what,
                   const char* plural) {
  long long k = 0;
  const auto [ptr, ec] = std::from_chars(ref.data(), ref.data() + ref.size(), k);
  if (ec != std::errc() || ptr != ref.data() + ref.size() || k == 0)
    throw Error(source + ": " + where + ": expected a " + what +
                " index (1-based, or negative), got '" + std::string(corner.substr(0, 32)) + "'");
  const long long n = static_cast<long long>(count);
  const long long index = k > 0 ? k - 1 : n + k;
  if (index < 0 || index >= n)
    throw Error(source + ": " + where + ": " + what + " index " + std::to_string(k) +
                " is out of range (" + std::to_string(n) + " " + plural + " so far)");
  return static_cast<unsigned>(index);
}

}  // namespace

Mesh parse_obj(std::string_view text, const std::string& source) {
  std::vector<Vec3f> positions, normals;
  // Each face corner: its position and its normal (~0u: none given).
  std::vector<std::array<std::pair<unsigned, unsigned>, 3>> corners;
  std::size_t pos = 0;
  long line_number = 0;
  std::vector<std::pair<unsigned, unsigned>> polygon;
  bool any_normal = false;
  while (pos < text.size()) {
    const std::size_t nl = text.find('\n', pos);
    const std::size_t end = nl == std::string_view::npos ? text.size() : nl;
    const std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_number;
    const std::vector<std::string_view> w = words(line);
    if (w.empty() || w[0].front() == '#') continue;
    const std::string where = "line " + std::to_string(line_number);
    if (w[0] == "v") {
      positions.push_back(obj_triple(w, source, where, "v"));
    } else if (w[0] == "vn") {
      normals.push_back(obj_triple(w, source, where, "vn"));
    } else if (w[0] == "f") {
      if (w.size() < 4) throw Error(source + ": " + where + ": a face needs at least 3 vertices");
      polygon.clear();
      for (std::size_t i = 1; i < w.size(); ++i) {
        // v, v/t, v/t/n or v//n.
        const std::string_view corner = w[i];
        const std::size_t slash = corner.find('/');
        const unsigned v = obj_index(corner.substr(0, slash), positions.size(), source, where,
                                     corner, "vertex", "vertices");
        unsigned n = ~0u;
        if (slash != std::string_view::npos) {
          const std::size_t second = corner.find('/', slash + 1);
          if (second != std::string_view::npos && second + 1 < corner.size()) {
            n = obj_index(corner.substr(second + 1), normals.size(), source, where, corner,
                          "normal", "normals");
            any_normal = true;
          }
        }
        polygon.emplace_back(v, n);
      }
      for (std::size_t j = 2; j < polygon.size(); ++j)
        corners.push_back({polygon[0], polygon[j - 1], polygon[j]});
    }
  }
  Mesh mesh;
  if (!any_normal) {
    mesh.positions = std::move(positions);
    for (const auto& t : corners) mesh.triangles.push_back({t[0].first, t[1].first, t[2].first});
    return mesh;
  }
  // With normals a vertex is a position and a normal: a corner of a hard edge (a cube's) is as
  // many vertices as normals meet there. Corners without one get a zero normal, which load_mesh
  // replaces by the area-weighted one.
  std::map<std::pair<unsigned, unsigned>, unsigned> vertex_of;
  for (const auto& t : corners) {
    std::array<unsigned, 3> triangle{};
    for (int k = 0; k < 3; ++k) {
      const auto [it, inserted] =
          vertex_of.try_emplace(t[std::size_t(k)], unsigned(mesh.positions.size()));
      if (inserted) {
        mesh.positions.push_back(positions[t[std::size_t(k)].first]);
        mesh.normals.push_back(t[std::size_t(k)].second == ~0u ? Vec3f::Zero()
                                                               : normals[t[std::size_t(k)].second]);
      }
      triangle[std::size_t(k)] = it->second;
    }
    mesh.triangles.push_back(triangle);
  }
  return mesh;
}

}  // namespace lucent::render
