// `lucent bench render`: per-stage times of the radiance-map technique at the seed's settings on
// the bunny and the dragon at several resolutions (Dal Corso 2014, Figure 6.15), to a CSV in the
// current folder or --out (notebooks_data/bench/ holds the shipped runs).
#pragma once

#include <array>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "lucent/render/hierarchical.h"
#include "lucent/render/render_settings.h"

namespace lucent::render {

struct RenderBenchOptions {
  std::filesystem::path out_csv = "render.csv";  ///< --out (default: the current folder)
  std::vector<std::string> meshes = {"bunny", "dragon:4", "dragon:3", "dragon:2"};
  RenderSettings settings;   ///< defaults: the seed's K = 16, W_s = W_l = 512, N = 50, M = 1000
  /// One row per mesh and selection: strata gathers far disc points, whose scattered light-map
  /// reads cost more than the seed's nearest ones.
  std::vector<DiscSelection> disc_selections = {DiscSelection::kStrata, DiscSelection::kNearest};
  int frames = 3;            ///< frames timed per mesh (per-stage means); few on llvmpipe
  int size = 512;            ///< output image, pixels square
  std::string material = "marble";
};

/// Renders each mesh with each disc selection, one row each; returns the rows written.
int run_render_bench(const RenderBenchOptions& options, std::ostream& log);

/// `lucent bench fur`: the fur tile of Klotzli & Olano at the seed's 1280 x 1024 (the seed: 40 fps
/// on a GeForce 6800 SLI), one row per shell count: the CPU precompute (hairs, cross-sections,
/// transfer) and the per-frame draw (glFinish and a wall clock; the median of `frames` after a
/// first, compiling frame), from the render command's default view (30, 20: the tile on part of the
/// frame) and from close by (the frame filled), with the fraction of pixels the fur covers.
struct FurBenchOptions {
  std::filesystem::path out_csv = "fur.csv";  ///< --out (default: the current folder)
  std::vector<int> shells = {16, 32, 64};  ///< the seed's 32 and a halving and doubling
  int texels = 64;                         ///< the seed's tile, texels across
  std::vector<float> distances = {3.4f, 1.6f};  ///< camera distances, bounding radii
  int frames = 5;
  int width = 1280, height = 1024;
  std::string material = "marble";
};

/// Times the tile at each shell count; returns the rows written.
int run_fur_bench(const FurBenchOptions& options, std::ostream& log);

/// `lucent bench hierarchical`: seed 004's modes on the CPU (the paper's Table 3 was CPU-bound
/// too, so its figures compare): per mesh, configuration and thread count, the linking (hierarchy,
/// links, their memory), a render-mode frame (the light turns), on-the-fly and incremental frames
/// of a deforming mesh (the sine deformer; the paper's case for both), the paper's figures beside;
/// and the links per triangle against the error of B from the all-pairs solution on one mesh.
/// Writes hierarchical.csv, hierarchical_error.csv and hierarchical.png into `out_dir`.
struct HierarchicalBenchOptions {
  std::filesystem::path out_dir = ".";
  /// The seed's 2,016 and 8,160 triangles (simplified from scans: its butterfly model is not
  /// public), and the dragon.
  std::vector<std::string> meshes = {"bunny@2016", "dragon:4@8160", "dragon:4", "dragon:3"};
  std::vector<int> threads = {1, 0};  ///< 0: every core
  int frames = 3;                     ///< timed frames per mode (median)
  float deform_amplitude = 0.02f;     ///< the sine deformer's, a fraction of the diagonal
  /// Incremental frames: factor evaluations per frame (the seed bounds them, without a figure):
  /// a tenth of the seed's links at 2,016 triangles.
  long incremental_budget = 9000;
  std::string material = "marble";
  /// The "seed table 3" configuration's oracle (its rule; the seed gives no thresholds): chosen
  /// from the error sweep as the most links within 2x the seed's per triangle.
  hierarchical::Options seed_thresholds = [] {
    hierarchical::Options o;
    o.epsilon_1 = 0.1;
    o.epsilon_2 = 0.8;
    o.min_planarity = 0.95;
    return o;
  }();
  std::string error_mesh = "bunny@2016";
  /// epsilon_1, epsilon_2, near (sr) and planarity per point of the error sweep.
  std::vector<std::array<double, 4>> error_sweep = {
      {0.02, 0.2, 0.02, 0.99}, {0.05, 0.4, 0.05, 0.99}, {0.1, 0.4, 0.05, 0.95},
      {0.1, 0.8, 0.05, 0.95},  {0.1, 0.8, 0.2, 0.95},   {0.2, 0.8, 0.05, 0.9},
      {0.2, 1.0, 0.1, 0.9}};
};
struct HierarchicalBenchResult {
  int rows = 0, error_rows = 0;
};
HierarchicalBenchResult run_hierarchical_bench(const HierarchicalBenchOptions& options,
                                               std::ostream& log);

/// "CPU model, N hardware threads; OpenGL: renderer" for the benchmarks' reports.
std::string machine_description(const std::string& gl_renderer);

}  // namespace lucent::render
