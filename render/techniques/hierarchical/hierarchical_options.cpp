// The hierarchical technique's options and statistics (parsing, checks, text), and the all-pairs
// reference the tests hold the solve against (hierarchical.h).
#include <cmath>
#include <sstream>

#include "lucent/core/error.h"
#include "lucent/materials/material.h"
#include "lucent/render/hierarchical.h"

namespace lucent::render::hierarchical {

Mode parse_mode(const std::string& text) {
  if (text == "render") return Mode::kRender;
  if (text == "incremental") return Mode::kIncremental;
  if (text == "on-the-fly") return Mode::kOnTheFly;
  throw Error("--hierarchical-mode: expected render, incremental or on-the-fly, got '" + text +
              "'");
}

std::string to_string(Mode mode) {
  return mode == Mode::kRender        ? "render"
         : mode == Mode::kIncremental ? "incremental"
                                      : "on-the-fly";
}

void Options::validate() const {
  auto positive = [](double v, const char* name) {
    if (!(v > 0) || !std::isfinite(v)) {
      throw Error(std::string(name) + ": expected a positive solid angle in sr, got " +
                  std::to_string(v));
    }
  };
  positive(epsilon_1, "--hierarchical-epsilon1");
  positive(epsilon_2, "--hierarchical-epsilon2");
  positive(near, "--hierarchical-near");
  if (!(min_planarity >= 0 && min_planarity <= 1)) {
    throw Error("--hierarchical-planarity: expected A'/A in [0, 1], got " +
                std::to_string(min_planarity));
  }
  if (!(form_factor.edge_constant > 0 && form_factor.edge_constant <= 2)) {
    throw Error("--hierarchical-edge-constant: expected a value in (0, 2] (the seed's 2/5), got " +
                std::to_string(form_factor.edge_constant));
  }
  if (budget < 1) throw Error("--hierarchical-budget: expected at least 1 form factor per frame");
  if (threads < 0)
    throw Error("--hierarchical-threads: expected 0 (every core) or more, got " +
                std::to_string(threads));
}

std::string Options::to_string() const {
  std::ostringstream s;
  s << "mode " << hierarchical::to_string(mode) << ", epsilon_1 " << epsilon_1 << " sr, epsilon_2 "
    << epsilon_2 << " sr, near " << near << " sr, planarity " << min_planarity << ", edge c "
    << form_factor.edge_constant << " (" << hierarchical::to_string(form_factor.rule) << ", dipole "
    << hierarchical::to_string(form_factor.placement) << "), budget " << budget
    << ", irradiance cache " << (irradiance_cache ? "on" : "off");
  return s.str();
}

std::string Stats::to_string() const {
  std::ostringstream s;
  s << triangles << " triangles, " << clusters << " clusters (depth " << depth << "), " << links
    << " links, " << form_factor_calls << " form factors (" << edge_segments << " edge segments), "
    << point_samples << " point samples; ms: link " << link_ms << ", irradiance " << irradiance_ms
    << ", pull " << pull_ms << ", gather " << gather_ms << ", push " << push_ms;
  if (demoted || promoted || refreshed) {
    s << "; incremental: " << demoted << " demoted, " << promoted << " promoted, " << refreshed
      << " refreshed";
  }
  return s.str();
}

std::vector<std::array<double, 3>> all_pairs_B(const Mesh& mesh,
                                               const materials::Material& material,
                                               const std::vector<std::array<double, 3>>& face_E,
                                               const FormFactorOptions& options) {
  std::array<materials::DiffusionCoefficients<double>, 3> c{};
  for (int ch = 0; ch < 3; ++ch)
    c[std::size_t(ch)] = materials::derive_coefficients(material.medium(ch));
  const std::size_t T = mesh.triangles.size();
  std::vector<Eigen::Vector3d> mid(T), normal(T);
  for (std::size_t t = 0; t < T; ++t) {
    const auto& tri = mesh.triangles[t];
    const Eigen::Vector3d a = mesh.positions[tri[0]].cast<double>(),
                          b = mesh.positions[tri[1]].cast<double>(),
                          d = mesh.positions[tri[2]].cast<double>();
    mid[t] = (a + b + d) / 3;
    const Eigen::Vector3d n = (b - a).cross(d - a);
    normal[t] = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::UnitZ();
  }
  std::vector<std::array<double, 3>> B(T, std::array<double, 3>{});
  for (std::size_t r = 0; r < T; ++r) {
    for (std::size_t e = 0; e < T; ++e) {
      const auto& tri = mesh.triangles[e];
      for (int ch = 0; ch < 3; ++ch) {
        if (face_E[e][std::size_t(ch)] == 0) continue;
        B[r][std::size_t(ch)] +=
            face_E[e][std::size_t(ch)] * triangle_form_factor(c[std::size_t(ch)], mid[r], normal[r],
                                                              mesh.positions[tri[0]].cast<double>(),
                                                              mesh.positions[tri[1]].cast<double>(),
                                                              mesh.positions[tri[2]].cast<double>(),
                                                              options);
      }
    }
  }
  return B;
}

}  // namespace lucent::render::hierarchical
