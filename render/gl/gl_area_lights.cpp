// Area lights on the GPU (gl_area_lights.h).
#include "gl_area_lights.h"

#include <cmath>
#include <string>

#include "area_light.h"
#include "lucent/core/error.h"

namespace lucent::render::gl {

namespace {

double radical_inverse(int base, int i) {
  double result = 0, f = 1.0 / base;
  for (; i > 0; i /= base, f /= base) result += f * (i % base);
  return result;
}

}  // namespace

bool has_area_lights(const std::vector<Light>& lights) {
  for (const Light& l : lights) {
    if (l.type == LightType::kArea) return true;
  }
  return false;
}

std::vector<std::string> area_light_defines(const std::vector<Light>& lights) {
  std::vector<std::string> d = {"LUCENT_MAX_AREA_LIGHTS " + std::to_string(kMaxAreaLights)};
  if (has_area_lights(lights)) d.push_back("LUCENT_AREA_LIGHTS");
  return d;
}

int area_slot(const std::vector<Light>& lights, std::size_t l) {
  if (lights[l].type != LightType::kArea) return -1;
  int slot = 0;
  for (std::size_t i = 0; i < l; ++i) slot += lights[i].type == LightType::kArea ? 1 : 0;
  if (slot >= kMaxAreaLights) {
    throw Error("--light: the real-time techniques take at most " +
                std::to_string(kMaxAreaLights) + " area lights");
  }
  return slot;
}

void upload_area_lights(GLuint program, const std::vector<Light>& lights) {
  const GLint location = glGetUniformLocation(program, "u_area_vertices");
  constexpr int V = kMaxPolygonVertices;
  std::vector<float> block(std::size_t(kMaxAreaLights) * V * 4, 0.0f);
  for (std::size_t l = 0; l < lights.size(); ++l) {
    const int slot = area_slot(lights, l);
    if (slot < 0) continue;
    const Light& light = lights[l];
    float* base = &block[std::size_t(slot) * V * 4];
    for (std::size_t i = 0; i < light.polygon.size(); ++i) {
      for (int c = 0; c < 3; ++c) base[i * 4 + std::size_t(c)] = light.polygon[i][c];
    }
    const Vec3f n = area_light_normal(light);
    base[3] = float(light.polygon.size());
    base[4 + 3] = float(area_light_area(light));
    for (int c = 0; c < 3; ++c) base[(2 + std::size_t(c)) * 4 + 3] = n[c];
  }
  if (location >= 0) glProgramUniform4fv(program, location, kMaxAreaLights * V, block.data());
}

Vec3f area_light_frame_point(const Light& light, std::size_t l, int t) {
  const double shift_s = radical_inverse(5, int(l) + 1), shift_t = radical_inverse(7, int(l) + 1);
  const double s = std::fmod(radical_inverse(2, t) + shift_s, 1.0);
  const double u = std::fmod(radical_inverse(3, t) + shift_t, 1.0);
  return area_light_point(light, s, u);
}

}  // namespace lucent::render::gl
