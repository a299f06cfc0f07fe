// `lucent bench render`: per-stage times of the radiance-map technique at the seed's settings on the
// bunny and the dragon at several resolutions (seed 003, Figure 6.15), to notebooks_data/bench/.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "lucent/render/render_settings.h"

namespace lucent::render {

struct RenderBenchOptions {
  std::filesystem::path out_csv = "notebooks_data/bench/render.csv";
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

}  // namespace lucent::render
