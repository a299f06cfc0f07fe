// `lucent bench hierarchical` (render_bench.h): seed 004's three modes timed on the CPU, where the
// paper timed them, beside its Table 3; and the links the oracle makes against the error they
// leave, against the all-pairs solution.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <ostream>
#include <sstream>
#include <thread>

#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/imaging/plot.h"
#include "lucent/materials/material.h"
#include "lucent/render/hierarchical.h"
#include "lucent/render/render_bench.h"
#include "lucent/render/scene.h"
#include "lucent/render/viewer_controls.h"

namespace lucent::render {
namespace {

using imaging::PlotFigure;
using imaging::PlotPanel;
using imaging::PlotSeries;

using Clock = std::chrono::steady_clock;
using Rgb = std::array<double, 3>;

double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// Seed 004's Table 3 (a marble butterfly subdivision model scaled at 2.5 cm; a dual Xeon 2.4 GHz,
// 2003): triangles, links per triangle, on-the-fly / incremental / render ms.
struct PaperRow {
  int triangles;
  double links_per_triangle, on_the_fly_ms, incremental_ms, render_ms;
};
constexpr PaperRow kTable3[] = {{2016, 44.1, 20, 8, 5},
                                {8160, 47.5, 47, 23, 13},
                                {32736, 53.3, 188, 68, 43},
                                {131736, 52.7, 722, 351, 199}};

const PaperRow* paper_row(std::size_t triangles) {
  for (const PaperRow& row : kTable3) {
    if (std::abs(double(triangles) - row.triangles) <= 0.05 * row.triangles) return &row;
  }
  return nullptr;
}

// Relative RMS of per-face B over faces and channels.
double relative_rms(const std::vector<Rgb>& b, const std::vector<Rgb>& ref) {
  double num = 0, den = 0;
  for (std::size_t t = 0; t < ref.size(); ++t)
    for (std::size_t c = 0; c < 3; ++c) {
      num += (b[t][c] - ref[t][c]) * (b[t][c] - ref[t][c]);
      den += ref[t][c] * ref[t][c];
    }
  return den > 0 ? std::sqrt(num / den) : 0;
}

// The key light turned by `degrees` about the vertical.
std::vector<Light> turned(std::vector<Light> lights, double degrees) {
  const double a = degrees * std::numbers::pi / 180;
  const float c = float(std::cos(a)), s = float(std::sin(a));
  for (Light& l : lights) {
    if (l.type == LightType::kDirectional) {
      l.direction = Vec3f(c * l.direction.x() + s * l.direction.z(), l.direction.y(),
                          -s * l.direction.x() + c * l.direction.z());
    }
  }
  return lights;
}

struct ModeTimes {
  double hierarchy_ms = 0, link_ms = 0, render_ms = 0, on_the_fly_ms = 0, incremental_ms = 0;
  long links = 0, on_the_fly_links = 0;
  double memory_mib = 0, on_the_fly_memory_mib = 0;
  double incremental_factors = 0;  // factor evaluations per incremental frame (median)
};

// The three modes on one scene: render (the links made once, then frames with the light turning),
// on-the-fly and incremental (frames of a deforming mesh: the sine deformer's positions, then the
// solve; the paper's case for both), frame times the median of `frames` after the first.
ModeTimes time_modes(const Scene& scene, hierarchical::Options o, int frames, float amplitude) {
  // (o.budget bounds the incremental frames' factor evaluations.)
  ModeTimes t;
  {
    o.mode = hierarchical::Mode::kRender;
    hierarchical::Solver solver(scene, o);
    solver.solve();
    t.hierarchy_ms = solver.stats().build_ms;
    t.link_ms = solver.stats().link_ms;
    t.links = solver.stats().links;
    t.memory_mib = solver.stats().memory_mib;
    std::vector<double> ms;
    for (int f = 0; f < frames; ++f) {
      const auto t0 = Clock::now();
      solver.set_lights(turned(scene.lights, 10.0 * (f + 1)));
      solver.solve();
      ms.push_back(ms_since(t0));
    }
    t.render_ms = median(ms);
  }
  const SineDeformer deformer(scene.mesh, amplitude);
  Mesh moved = scene.mesh;
  for (const auto mode : {hierarchical::Mode::kOnTheFly, hierarchical::Mode::kIncremental}) {
    o.mode = mode;
    hierarchical::Solver solver(scene, o);
    solver.solve();
    std::vector<double> ms, factors;
    for (int f = 0; f < frames; ++f) {
      deformer.apply(0.1 * (f + 1), moved);
      const auto t0 = Clock::now();
      solver.set_geometry(moved.positions, moved.normals);
      solver.solve();
      ms.push_back(ms_since(t0));
      factors.push_back(
          double(solver.stats().refreshed + 2 * solver.stats().demoted + solver.stats().promoted));
    }
    if (mode == hierarchical::Mode::kOnTheFly) {
      t.on_the_fly_ms = median(ms);
      t.on_the_fly_links = solver.stats().links;
      t.on_the_fly_memory_mib = solver.stats().memory_mib;
    } else {
      t.incremental_ms = median(ms);
      t.incremental_factors = median(factors);
    }
  }
  return t;
}

struct Config {
  std::string name;
  double object_size_mm;
  bool geometry_factor;
  hierarchical::Options options;
};

// lucent's defaults (100 mm, the shape's factor, Gauss-Legendre edges) and the seed's Table 3
// setting (2.5 cm, the plain dipole, the midpoint rule, thresholds that make the paper's link count
// per triangle within 2x on a smooth mesh: HierarchicalBenchOptions).
std::vector<Config> configs(const HierarchicalBenchOptions& options) {
  Config lucent{"lucent defaults", 100.0, true, {}};
  Config seed{"seed table 3", 25.0, false, options.seed_thresholds};
  seed.options.form_factor.rule = hierarchical::SegmentRule::kSeedMidpoint;
  return {lucent, seed};
}

Scene bench_scene(const std::string& mesh, const std::string& material, const Config& config) {
  Scene scene;
  scene.mesh = load_mesh(mesh, config.object_size_mm);
  scene.material = materials::load_material(material);
  scene.geometry_factor = config.geometry_factor;
  scene.angular = false;
  scene.single_scattering = false;
  scene.lights = {parse_light("directional:-0.366,1,1.37:1,1,1"),
                  parse_light("directional:1.12,0.3,-0.067:0.3,0.3,0.3")};
  return scene;
}

}  // namespace

HierarchicalBenchResult run_hierarchical_bench(const HierarchicalBenchOptions& options,
                                               std::ostream& log) {
  if (options.frames < 1) throw Error("bench hierarchical: expected --frames >= 1");
  // Every mesh and the material read first: a bad name fails at once, not after minutes of rows.
  materials::load_material(options.material);
  for (const std::string& mesh : options.meshes) load_mesh(mesh, 100.0);
  load_mesh(options.error_mesh, 100.0);
  HierarchicalBenchResult result;
  const std::string machine = machine_description("not used");
  const std::string cpu = machine.substr(0, machine.find(';'));

  // The links against the error, on one mesh, against the all-pairs solution (no hierarchy).
  std::ostringstream error_csv;
  error_csv << "mesh,triangles,object_size_mm,epsilon_1,epsilon_2,near,planarity,rule,links,"
               "links_per_triangle,relative_rms_B,link_ms\n";
  PlotSeries sweep_series;
  const Config seed = configs(options)[1];
  sweep_series.label =
      "lucent (" + options.error_mesh + ", " + std::to_string(int(seed.object_size_mm)) + " mm)";
  {
    const Scene scene = bench_scene(options.error_mesh, options.material, seed);
    std::vector<Rgb> reference;
    for (const auto& [e1, e2, near, planarity] : options.error_sweep) {
      hierarchical::Options o = seed.options;
      o.epsilon_1 = e1;
      o.epsilon_2 = e2;
      o.near = near;
      o.min_planarity = planarity;
      o.form_factor.rule = hierarchical::SegmentRule::kGauss2;  // the error of the links alone
      hierarchical::Solver solver(scene, o);
      solver.solve();
      if (reference.empty()) {
        const auto t0 = Clock::now();
        reference =
            hierarchical::all_pairs_B(scene.mesh, scene.material, solver.face_E(), o.form_factor);
        log << "  all pairs on " << options.error_mesh << " (" << scene.mesh.triangles.size()
            << " triangles): " << ms_since(t0) / 1000 << " s\n";
      }
      const double error = relative_rms(solver.face_B(), reference);
      const double per = double(solver.stats().links) / double(scene.mesh.triangles.size());
      error_csv << options.error_mesh << ',' << scene.mesh.triangles.size() << ','
                << seed.object_size_mm << ',' << e1 << ',' << e2 << ',' << near << ',' << planarity
                << ",gauss2," << solver.stats().links << ',' << per << ',' << error << ','
                << solver.stats().link_ms << '\n';
      sweep_series.x.push_back(per);
      sweep_series.y.push_back(100 * error);
      log << "  epsilon " << e1 << '/' << e2 << " near " << near << " planarity " << planarity
          << ": " << per << " links per triangle, B " << 100 * error << "% from all pairs\n";
      ++result.error_rows;
    }
  }

  std::ostringstream csv;
  csv << "mesh,triangles,config,object_size_mm,threads,hierarchy_ms,link_ms,links,links_per_"
         "triangle,memory_mib,render_ms,on_the_fly_ms,on_the_fly_memory_mib,incremental_ms,"
         "incremental_factors,paper_links_per_triangle,paper_on_the_fly_ms,paper_incremental_ms,"
         "paper_render_ms,cpu\n";
  std::vector<PlotSeries> mode_series(3);
  mode_series[0].label = "on-the-fly";
  mode_series[1].label = "incremental";
  mode_series[2].label = "render";
  const std::array<std::array<std::uint8_t, 3>, 3> colours = {
      {{200, 40, 40}, {40, 140, 40}, {40, 70, 200}}};
  for (const std::string& mesh : options.meshes) {
    for (const Config& config : configs(options)) {
      const Scene scene = bench_scene(mesh, options.material, config);
      for (const int threads : options.threads) {
        hierarchical::Options o = config.options;
        o.threads = threads;
        o.budget = options.incremental_budget;
        const ModeTimes t = time_modes(scene, o, options.frames, options.deform_amplitude);
        const std::size_t T = scene.mesh.triangles.size();
        const PaperRow* paper = paper_row(T);
        const int used =
            threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency()));
        csv << mesh << ',' << T << ",\"" << config.name << "\"," << config.object_size_mm << ','
            << used << ',' << t.hierarchy_ms << ',' << t.link_ms << ',' << t.links << ','
            << double(t.links) / double(T) << ',' << t.memory_mib << ',' << t.render_ms << ','
            << t.on_the_fly_ms << ',' << t.on_the_fly_memory_mib << ',' << t.incremental_ms << ','
            << t.incremental_factors << ',';
        if (paper) {
          csv << paper->links_per_triangle << ',' << paper->on_the_fly_ms << ','
              << paper->incremental_ms << ',' << paper->render_ms;
        } else {
          csv << ",,,";
        }
        csv << ",\"" << cpu << "\"\n";
        log << "  " << mesh << " (" << T << " triangles), " << config.name << ", " << used
            << " threads: link " << t.link_ms << " ms (" << t.links << " links, "
            << double(t.links) / double(T) << " a triangle, " << t.memory_mib
            << " MiB); frames: render " << t.render_ms << " ms, on-the-fly " << t.on_the_fly_ms
            << " ms, incremental " << t.incremental_ms << " ms";
        if (paper) {
          log << " (seed: " << paper->on_the_fly_ms << " / " << paper->incremental_ms << " / "
              << paper->render_ms << " ms, " << paper->links_per_triangle << " links a triangle)";
        }
        log << '\n';
        if (config.name == "seed table 3" && used > 1) {
          for (int m = 0; m < 3; ++m) mode_series[std::size_t(m)].x.push_back(double(T));
          mode_series[0].y.push_back(t.on_the_fly_ms);
          mode_series[1].y.push_back(t.incremental_ms);
          mode_series[2].y.push_back(t.render_ms);
        }
        ++result.rows;
      }
    }
  }

  // The figure: the modes' frames against the paper's, and the links against the error.
  PlotFigure figure;
  PlotPanel modes;
  modes.title = "Seed 004's modes: lucent (seed table 3 setting, all threads) and the paper";
  modes.x_label = "triangles";
  modes.y_label = "frame (ms)";
  modes.log_x = modes.log_y = true;
  for (int m = 0; m < 3; ++m) {
    PlotSeries paper;
    paper.label = mode_series[std::size_t(m)].label + " (seed, 2003 CPU)";
    paper.dashed = paper.line = true;
    paper.rgb = colours[std::size_t(m)];
    paper.marker = imaging::Marker::kSquare;
    mode_series[std::size_t(m)].rgb = colours[std::size_t(m)];
    for (const PaperRow& row : kTable3) {
      paper.x.push_back(row.triangles);
      paper.y.push_back(m == 0 ? row.on_the_fly_ms : m == 1 ? row.incremental_ms : row.render_ms);
    }
    mode_series[std::size_t(m)].label += " (lucent)";
    mode_series[std::size_t(m)].line = true;
    modes.series.push_back(mode_series[std::size_t(m)]);
    modes.series.push_back(paper);
  }
  PlotPanel links;
  links.title = "Links per triangle against the error of B (all pairs the truth)";
  links.x_label = "links per triangle";
  links.y_label = "relative RMS of B (%)";
  links.log_y = true;
  links.series.push_back(sweep_series);
  links.reference_lines.push_back({44.1, true, false});
  links.reference_lines.push_back({2 * 44.1, true, true});
  figure.panels = {modes, links};
  figure.footer = {
      "Vertical lines: the seed's 44.1 links a triangle at 2,016 triangles and twice "
      "that. " +
      machine.substr(0, machine.find(';'))};
  // The figure first: the one write that can fail on its own (no cairo driver) before the CSVs.
  imaging::write_plot(options.out_dir / "hierarchical.png", figure);
  write_file_atomically(options.out_dir / "hierarchical.csv", csv.str());
  write_file_atomically(options.out_dir / "hierarchical_error.csv", error_csv.str());
  return result;
}

}  // namespace lucent::render
