// `lucent bench render`: per-stage times of the radiance-map technique at the seed's settings on
// the bunny and the dragon at several resolutions (Dal Corso 2014, Figure 6.15), to a CSV in the
// current folder or --out (notebooks_data/bench/ holds the shipped runs).
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

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

}  // namespace lucent::render
