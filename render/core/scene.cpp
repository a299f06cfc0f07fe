// Lights from the command line, the orbit camera
// (render/include/lucent/render/scene.h).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "area_light.h"
#include "lucent/core/error.h"
#include "lucent/render/scene.h"

namespace lucent::render {

namespace {

// "A,B,C" -> three finite floats, or nothing.
bool parse_triple(const std::string& text, Vec3f& out) {
  std::istringstream in(text);
  std::string field;
  int n = 0;
  while (std::getline(in, field, ',')) {
    if (n == 3 || field.empty()) return false;
    char* end = nullptr;
    const double v = std::strtod(field.c_str(), &end);
    if (end == field.c_str() || *end != '\0' || !std::isfinite(v)) return false;
    out[n++] = static_cast<float>(v);
  }
  return n == 3 && text.back() != ',';
}

}  // namespace

Light parse_light(const std::string& text) {
  const std::string expected =
      "expected directional:DX,DY,DZ:R,G,B (direction toward the light), point:X,Y,Z:R,G,B "
      "(position in mm) or rect:CX,CY,CZ:UX,UY,UZ:VX,VY,VZ:R,G,B (centre and half-edge vectors in "
      "mm, radiance; emitting toward U x V)";
  const auto bad = [&](const std::string& why) { return Error("--light '" + text + "': " + why); };
  std::vector<std::string> fields;
  {
    std::size_t start = 0;
    while (true) {
      const std::size_t colon = text.find(':', start);
      fields.push_back(text.substr(start, colon == std::string::npos ? colon : colon - start));
      if (colon == std::string::npos) break;
      start = colon + 1;
    }
  }
  const std::string kind = fields.front();
  if (kind == "rect") {
    if (fields.size() != 5) throw bad(expected);
    Vec3f c, u, v, radiance;
    const char* names[] = {"centre", "U", "V"};
    Vec3f* out[] = {&c, &u, &v};
    for (int i = 0; i < 3; ++i) {
      if (!parse_triple(fields[std::size_t(i) + 1], *out[i])) {
        throw bad(std::string("the ") + names[i] + " must be three comma-separated numbers; " +
                  expected);
      }
    }
    if (!parse_triple(fields[4], radiance)) {
      throw bad("the radiance must be three comma-separated numbers R,G,B; " + expected);
    }
    if ((radiance.array() < 0).any()) throw bad("the radiance must not be negative");
    return rect_light(c, u, v, radiance, "--light '" + text + "'");
  }
  if (fields.size() != 3) throw bad(expected);
  const std::string& where = fields[1];
  const std::string& colour = fields[2];
  Light light;
  if (kind == "directional") {
    light.type = LightType::kDirectional;
  } else if (kind == "point") {
    light.type = LightType::kPoint;
  } else {
    throw bad("unknown light type '" + kind + "'; " + expected);
  }
  Vec3f v;
  if (!parse_triple(where, v)) {
    throw bad(std::string(light.type == LightType::kPoint ? "position" : "direction") +
              " must be three comma-separated numbers; " + expected);
  }
  if (light.type == LightType::kDirectional) {
    if (!(v.norm() > 0)) throw bad("the direction must not be zero");
    light.direction = v.normalized();
  } else {
    // A light farther than 1 km from a scene of at most 1 km (kMaxObjectSizeMm) is a directional
    // one; positions beyond it overflow the ray queries' float ranges.
    if (!(v.cwiseAbs().maxCoeff() <= 1e6f)) {
      throw bad("the position must be within 1e6 mm of the mesh centre (use a directional light "
                "for a light that far)");
    }
    light.position = v;
  }
  if (!parse_triple(colour, light.radiance)) {
    throw bad("the colour must be three comma-separated numbers R,G,B; " + expected);
  }
  if ((light.radiance.array() < 0).any()) throw bad("the colour must not be negative");
  // Radiometry in float: 1e38 overflows to infinity at the first product. Images are relative, so
  // nothing is lost by asking for values a float can carry through the renderer's sums.
  if (!(light.radiance.maxCoeff() <= 1e12f)) throw bad("each of R,G,B must be at most 1e12");
  return light;
}

Camera orbit_camera(const Mesh& mesh, float azimuth_deg, float elevation_deg, float distance_radii,
                    int width, int height) {
  if (!(distance_radii > 0) || !std::isfinite(distance_radii)) {
    throw Error("--view: the distance must be positive (bounding-sphere radii), got " +
                std::to_string(distance_radii));
  }
  if (width <= 0 || height <= 0) {
    throw Error("--size: the image must be at least 1x1 pixels, got " + std::to_string(width) +
                "x" + std::to_string(height));
  }
  constexpr float kDeg = std::numbers::pi_v<float> / 180.0f;
  const float az = azimuth_deg * kDeg, el = elevation_deg * kDeg;
  // Azimuth turns about +y starting from +z; elevation lifts out of the xz-plane.
  const Vec3f offset(std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az));
  Camera camera;
  camera.target = mesh.centre();
  camera.eye = camera.target + distance_radii * mesh.bounding_radius() * offset;
  // Looking straight down or up, +y is the view direction itself: use the horizontal direction
  // the camera would have turned from as "up" so the image keeps its azimuth.
  if (std::abs(std::cos(el)) < 1e-4f) {
    camera.up = Vec3f(-std::sin(az), 0, -std::cos(az)) * (el > 0 ? 1.0f : -1.0f);
  }
  camera.fov_y_deg = 35;
  camera.width = width;
  camera.height = height;
  return camera;
}

}  // namespace lucent::render
