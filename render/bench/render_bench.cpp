#include "lucent/render/render_bench.h"

#include <algorithm>
#include <ostream>
#include <sstream>

#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/render/fur_renderer.h"
#include "lucent/render/gl_context.h"
#include "lucent/render/radiance_maps.h"
#include "lucent/render/scene.h"

namespace lucent::render {

int run_render_bench(const RenderBenchOptions& options, std::ostream& log) {
  std::ostringstream csv;
  csv << "mesh,triangles,K,W_s,W_l,N,M,disc,frames,size_px,light_map_ms,radiance_map_ms,mip_blur_"
         "ms,final_ms,frame_ms,setup_ms,memory_mib,seed_formula_mib,device\n";
  RenderSettings settings = options.settings;
  settings.frames = options.frames;
  settings.validate();
  int rows = 0;
  for (const std::string& name : options.meshes) {
    Scene scene;
    scene.material = materials::load_material(options.material);
    scene.mesh = load_mesh(name, 100.0);
    scene.lights = {parse_light("directional:1,1,1:1,1,1")};
    scene.camera = orbit_camera(scene.mesh, 30, 20, 4, options.size, options.size);
    for (const DiscSelection selection : options.disc_selections) {
      settings.disc_selection = selection;
      RenderStats stats;
      render_radiance_maps(scene, settings, &stats);
      double stage[4] = {0, 0, 0, 0}, setup = 0;
      const char* names[4] = {"light map", "radiance map", "mip blur", "final"};
      for (const auto& [pass, ms] : stats.pass_ms) {
        for (int k = 0; k < 4; ++k) {
          if (pass == names[k]) stage[k] = ms;
        }
        if (pass == "setup") setup = ms;
      }
      const std::string device = stats.details.value("gl_renderer", std::string("unknown"));
      // The maps' GPU memory and Dal Corso's formula for it (Table 5.1; radiance_maps.h).
      const nlohmann::json memory = stats.details.value("memory_mib", nlohmann::json::object());
      csv << name << ',' << scene.mesh.triangles.size() << ',' << settings.directions << ','
          << settings.radiance_map_size << ',' << settings.light_map_size << ',' << settings.samples
          << ',' << settings.disc_points << ',' << to_string(settings.disc_selection) << ','
          << settings.frames << ',' << options.size << ',' << stage[0] << ',' << stage[1] << ','
          << stage[2] << ',' << stage[3] << ',' << stage[0] + stage[1] + stage[2] + stage[3] << ','
          << setup << ',' << memory.value("total", 0.0) << ',' << memory.value("seed_formula", 0.0)
          << ",\"" << device << "\"\n";
      log << "  " << name << " (" << scene.mesh.triangles.size() << " triangles, "
          << to_string(selection) << "): light map " << stage[0] << " ms, radiance map " << stage[1]
          << " ms, mip blur " << stage[2] << " ms, final " << stage[3] << " ms per frame on "
          << device << '\n';
      ++rows;
    }
  }
  write_file_atomically(options.out_csv, csv.str());
  return rows;
}

int run_fur_bench(const FurBenchOptions& options, std::ostream& log) {
  if (options.frames < 1 || options.width < 1 || options.height < 1) {
    throw Error("bench fur: expected --frames >= 1 and a positive --size");
  }
  const auto context = GlContext::create_headless();
  const std::string device = context->describe();
  Scene scene;
  scene.material = materials::load_material(options.material);
  scene.mesh = load_mesh("tile", 100.0);
  scene.lights = {parse_light("directional:1,1,1:1,1,1")};
  std::ostringstream csv;
  csv << "texels,shells,hairs,width_px,height_px,distance_radii,covered,frames,precompute_ms,"
         "draw_ms_median,draw_ms_min,fps,device\n";
  int rows = 0;
  for (const int shells : options.shells) {
   for (const float distance : options.distances) {
    scene.camera = orbit_camera(scene.mesh, 30, 20, distance, options.width, options.height);
    fur::FurOptions fur;
    fur.texels = options.texels;
    fur.shells = shells;
    // The seed's hair density at 64 x 64 texels, as `lucent render` scales it.
    const double scale = double(options.texels) * options.texels / (64.0 * 64.0);
    fur.overcoat.hairs = int(std::lround(600 * scale));
    fur.undercoat.hairs = int(std::lround(2400 * scale));
    fur.validate();
    FurRenderer renderer;
    renderer.setup(scene, fur);
    renderer.render_frame();  // compiles the shaders on first use
    std::vector<double> ms;
    for (int f = 0; f < options.frames; ++f) {
      renderer.render_frame();
      ms.push_back(renderer.draw_ms());
    }
    std::sort(ms.begin(), ms.end());
    const ImageRgb image = renderer.read_image();
    std::size_t covered = 0;
    for (std::size_t i = 0; i + 2 < image.data.size(); i += 3) {
      covered += (image.data[i] > 0 || image.data[i + 1] > 0 || image.data[i + 2] > 0) ? 1 : 0;
    }
    const double covered_fraction = 3.0 * double(covered) / double(image.data.size());
    const double median = ms.size() % 2 == 1 ? ms[ms.size() / 2]
                                             : 0.5 * (ms[ms.size() / 2 - 1] + ms[ms.size() / 2]);
    csv << fur.texels << ',' << shells << ',' << fur.overcoat.hairs + fur.undercoat.hairs << ','
        << options.width << ',' << options.height << ',' << distance << ',' << covered_fraction
        << ',' << options.frames << ',' << renderer.precompute_ms() << ',' << median << ',' << ms.front() << ',' << 1000.0 / median
        << ",\"" << device << "\"\n";
    log << "  fur tile " << fur.texels << "^2 x " << shells << " shells at " << options.width << 'x'
        << options.height << " (" << distance << " radii, " << 100 * covered_fraction
        << "% of the pixels): precompute " << renderer.precompute_ms() << " ms, draw " << median
        << " ms (median of " << options.frames << "; " << 1000.0 / median << " fps) on " << device
        << '\n';
    ++rows;
   }
  }
  write_file_atomically(options.out_csv, csv.str());
  return rows;
}

}  // namespace lucent::render
