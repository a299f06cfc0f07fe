// A wide flat slab lit and seen along its normal, and the closed form of its centre radiance (see
// slab_truth_test.cpp): shared by the tests that hold renders against truth.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "lucent/materials/fresnel.h"
#include "lucent/materials/material.h"
#include "lucent/materials/profile_table.h"
#include "lucent/render/render_settings.h"
#include "lucent/render/scene.h"

namespace lucent::render::testing_slab {

/// integral over the square [-h, h]^2 of f(|x|) dA = integral of f(r) l(r) dr, l(r) the length of
/// the circle of radius r inside the square (2 pi r up to h, 8 r (pi/4 - acos(h/r)) up to h
/// sqrt 2); trapezoid in ln r from 1e-7 h (f is finite at 0: the rest is f(0) pi r^2).
template <typename F>
double face_integral(F&& f, double h) {
  const int n = 20000;
  const double lo = 1e-7 * h, hi = h * std::sqrt(2.0);
  const double step = std::log(hi / lo) / n;
  const auto integrand = [&](double r) {
    const double arc = r <= h ? 2 * std::numbers::pi
                              : 8 * (std::numbers::pi / 4 - std::acos(std::min(1.0, h / r)));
    return f(r) * arc * r * r;  // f l(r) dr = f theta(r) r^2 d ln r
  };
  double sum = 0.5 * (integrand(lo) + integrand(hi));
  for (int i = 1; i < n; ++i) sum += integrand(lo * std::exp(step * i));
  return sum * step + f(lo) * std::numbers::pi * lo * lo;
}

/// Appends the axis-aligned box [lo, hi] to m: 6 faces of 2 triangles, 4 vertices each with the
/// face's outward normal (sharp edges), counter-clockwise seen from outside.
inline void add_box(Mesh& m, const Vec3f& lo, const Vec3f& hi) {
  const auto quad = [&m](Vec3f n, Vec3f a, Vec3f b, Vec3f c, Vec3f d) {
    const unsigned base = unsigned(m.positions.size());
    for (const Vec3f& p : {a, b, c, d}) {
      m.positions.push_back(p);
      m.normals.push_back(n);
    }
    m.triangles.push_back({base, base + 1, base + 2});
    m.triangles.push_back({base, base + 2, base + 3});
  };
  const float x0 = lo.x(), y0 = lo.y(), z0 = lo.z(), x1 = hi.x(), y1 = hi.y(), z1 = hi.z();
  quad({0, 1, 0}, {x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0});
  quad({0, -1, 0}, {x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1});
  quad({1, 0, 0}, {x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1});
  quad({-1, 0, 0}, {x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, z0});
  quad({0, 0, 1}, {x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1});
  quad({0, 0, -1}, {x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0});
}

struct SlabScene {
  Scene scene;
  double half_width_mm = 100;  // of the lit face
  double irradiance = 1;
};

/// A 2h x 50 x 2h mm box (top face at y = 25) lit by directional:0,1,0:1,1,1, seen from 300 mm
/// above the face's centre through a 4 degree field (the image spans +-10 mm of it).
inline SlabScene make_slab_scene(const std::string& material, int pixels, double h = 100) {
  SlabScene s;
  s.half_width_mm = h;
  Mesh& m = s.scene.mesh;
  m.name = "slab";
  const float y = 25.0f;  // the lit face
  add_box(m, Vec3f(-float(h), -y, -float(h)), Vec3f(float(h), y, float(h)));
  s.scene.material = materials::load_material(material);
  s.scene.lights = {parse_light("directional:0,1,0:1,1,1")};
  s.scene.specular = false;  // the closed form is the subsurface term (the mirror highlight sits
                             // exactly at the centre here)
  Camera& camera = s.scene.camera;
  camera.eye = Vec3f(0, y + 300, 0);
  camera.target = Vec3f(0, y, 0);
  camera.up = Vec3f(0, 0, -1);
  camera.fov_y_deg = 4;
  camera.width = camera.height = pixels;
  return s;
}

/// The closed form of the radiance at the lit face's centre for `model`, channel c (see the file
/// comment of slab_truth_test.cpp).
inline double centre_truth(const SlabScene& s, materials::DiffusionModel model, int c) {
  const materials::Material& m = s.scene.material;
  const double integral = face_integral(
      [&](double r) {
        return materials::radial_profile_value(m, c, model, materials::TableQuantity::kRadiance, r);
      },
      s.half_width_mm);
  return materials::fresnel_transmittance(1.0, m.ior) * s.irradiance * integral / std::numbers::pi;
}

/// The single scattering leaving the plane boundary of a semi-infinite medium (y < 0, channel c)
/// lit by a sun of irradiance 1 from the unit w_i and seen from the unit w_o (both y > 0): the
/// integral along the refracted view ray of the refracted collimated beam (Hanrahan and Krueger
/// 1993's first order),
///   L = F_t(cos_i) F_t(cos_o) cos_i sigma_s p_g(d_in . d_out) / (eta^2 sigma_t (cos_ti + cos_to)),
/// d_in the light's refracted travel direction, d_out the refracted view ray's reverse.
inline double single_scattering_truth(const materials::Material& material, int c,
                                      const Eigen::Vector3d& w_i, const Eigen::Vector3d& w_o) {
  const materials::Medium<double> m = material.medium(c);
  const double eta = material.ior;
  const auto inside = [&](const Eigen::Vector3d& w) {  // the refracted travel direction from w
    const double cos_t = std::sqrt(1 - (1 - w.y() * w.y()) / (eta * eta));
    return Eigen::Vector3d(-w.x() / eta, -cos_t, -w.z() / eta);
  };
  const Eigen::Vector3d d_in = inside(w_i), d_out = -inside(w_o);
  const double phase = materials::henyey_greenstein(m.g, d_in.dot(d_out));
  return materials::fresnel_transmittance(w_i.y(), eta) *
         materials::fresnel_transmittance(w_o.y(), eta) * w_i.y() * m.sigma_s * phase /
         (eta * eta * (m.sigma_a + m.sigma_s) * (-d_in.y() + d_out.y()));
}

/// Mean of channel c over the image (all of it sees the face).
inline double centre_mean(const ImageRgb& image, int c) {
  double sum = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) sum += image.at(x, y, c);
  return sum / (double(image.width) * image.height);
}

}  // namespace lucent::render::testing_slab
