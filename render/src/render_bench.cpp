#include "lucent/render/render_bench.h"

#include <ostream>
#include <sstream>

#include "lucent/materials/atomic_file.h"
#include "lucent/render/radiance_maps.h"
#include "lucent/render/scene.h"

namespace lucent::render {

int run_render_bench(const RenderBenchOptions& options, std::ostream& log) {
  std::ostringstream csv;
  csv << "mesh,triangles,K,W_s,W_l,N,M,disc,frames,size_px,light_map_ms,radiance_map_ms,mip_blur_"
         "ms,"
         "final_ms,frame_ms,setup_ms,device\n";
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
      csv << name << ',' << scene.mesh.triangles.size() << ',' << settings.directions << ','
          << settings.radiance_map_size << ',' << settings.light_map_size << ',' << settings.samples
          << ',' << settings.disc_points << ',' << to_string(settings.disc_selection) << ','
          << settings.frames << ',' << options.size << ',' << stage[0] << ',' << stage[1] << ','
          << stage[2] << ',' << stage[3] << ',' << stage[0] + stage[1] + stage[2] + stage[3] << ','
          << setup << ",\"" << device << "\"\n";
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

}  // namespace lucent::render
