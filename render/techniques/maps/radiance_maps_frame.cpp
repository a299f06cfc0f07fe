// The radiance maps' frame-by-frame API (radiance_maps.h): scene changes, frames, read-back,
// and render_radiance_maps.
#include "lucent/render/technique.h"
#include "radiance_maps_impl.h"

#include <algorithm>
#include <cstdio>

namespace lucent::render {

void RadianceMapRenderer::set_camera(const Camera& camera) {
  if (impl_->stage <= Impl::kSetupFinalAndUniforms) {  // the final target is built from it later
    impl_->scene.camera = camera;
    return;
  }
  if (camera.width != impl_->final.width() || camera.height != impl_->final.height()) {
    impl_->final.resize(camera.width, camera.height);
  }
  impl_->scene.camera = camera;
  impl_->final_stale = true;  // a split frame's partial calls draw the last sum from here
}

void RadianceMapRenderer::set_lights(const std::vector<Light>& lights) {
  if (lights.empty() || int(lights.size()) > kMaxLights) {
    throw Error("--light: the radiance maps take 1 to " + std::to_string(kMaxLights) + " lights");
  }
  impl_->finish_setup();
  const bool resize = int(lights.size()) != impl_->L;
  impl_->scene.lights = lights;
  impl_->L = int(lights.size());
  if (resize) {
    impl_->build_light_maps();
    impl_->stats.memory = maps_memory(impl_->settings, impl_->L, impl_->levels);
  }
  if (gl::has_area_lights(lights) != impl_->programs_have_area_lights) {
    // The programs' area-light branches come and go with the lights (gl_area_lights.h).
    impl_->build_programs();
    impl_->upload_layers();
    impl_->upload_material();  // and the lights
  } else {
    impl_->upload_lights();
  }
  restart();
}

void RadianceMapRenderer::set_geometry(const std::vector<Vec3f>& positions,
                                       const std::vector<Vec3f>& normals) {
  Impl& m = *impl_;
  m.finish_setup();
  gl::update_mesh(m.mesh, m.scene.mesh, positions, normals, "radiance maps");
  m.scene.mesh.positions = positions;
  m.scene.mesh.normals = normals;
  // Nothing is precomputed per mesh beyond what depends on its bounds: the layer and light cameras
  // are refitted, the radiance maps' depth pre-pass redone, and accumulation restarts.
  m.centre = m.scene.mesh.centre();
  m.radius_mm = m.scene.mesh.bounding_radius();
  m.upload_layers();
  m.upload_lights();
  m.render_radiance_depth(0, m.K);
  restart();
}

void RadianceMapRenderer::set_material(const materials::Material& material) {
  impl_->finish_setup();
  impl_->scene.material = material;
  impl_->upload_material();
  restart();
}

void RadianceMapRenderer::restart() {
  Impl& m = *impl_;
  m.frame = 0;
  m.level = 0;
  m.next_unit = 0;
  m.light_map_valid = false;
  m.last_image.clear();
  // What the set-up and the disc measured stays; the frames' figures start again.
  const RadianceMapStats kept = m.stats;
  m.stats = RadianceMapStats{};
  m.stats.gl_renderer = kept.gl_renderer;
  m.stats.memory = kept.memory;
  m.stats.setup_ms = kept.setup_ms;
  m.stats.depth_pass_ms = kept.depth_pass_ms;
  m.stats.warm_up_layer_ms = kept.warm_up_layer_ms;
  m.stats.warm_up_final_ms = kept.warm_up_final_ms;
  m.stats.sigma_star_per_mm = kept.sigma_star_per_mm;
  m.stats.disc_radius_mm = kept.disc_radius_mm;
  m.stats.used_disc_radius_mm = kept.used_disc_radius_mm;
  m.stats.samples_per_light = kept.samples_per_light;
}

bool RadianceMapRenderer::render_frame() {
  Impl& m = *impl_;
  m.finish_setup();  // staged: what prepare_step() has not done yet
  const bool accumulate = m.frame < m.settings.frames;
  if (accumulate && m.next_unit == 0) {
    if (m.has_area_lights()) {
      // Each accumulated frame sees the area lights from new points of their polygons.
      m.upload_light_cameras(m.frame + 1);
      m.light_map_valid = false;
    }
  }
  if (!m.light_map_valid) {
    m.timed(kLightMap, [&] { m.render_light_map(); });
    m.light_map_valid = true;
    ++m.stats.light_map_renders;
  }
  m.last_call_units = 0;
  if (accumulate) {
    const int total = m.K * m.bands;
    const int count = m.units_per_call > 0 ? std::min(m.units_per_call, total - m.next_unit)
                                           : total - m.next_unit;
    m.timed(kRadianceMap, [&] { m.render_radiance(m.frame + 1, m.next_unit, count); });
    m.last_call_units = count;
    m.next_unit += count;
    if (m.next_unit < total) {
      // The frame goes on at the next call; the last finished sum (radiance[current], which this
      // frame does not write) is shown, drawn anew when the camera moved or the image was resized.
      if (m.final_stale && m.frame > 0) m.timed(kFinal, [&] { m.render_final(); });
      gl::check_errors("a part of a radiance-map frame");
      return true;
    }
    m.next_unit = 0;
    ++m.frame;
    m.current = m.frame % 2;
    m.level = detail::blur_level_for_frame(m.frame, m.settings.frames,
                                           std::min(m.options.max_blur_level, m.levels - 1));
    m.timed(kMipBlur, [&] { m.render_blur(); });
    m.stats.frames = m.frame;
  }
  m.timed(kFinal, [&] { m.render_final(); });
  ++m.stats.frames_rendered;
  if (accumulate && m.options.convergence_tolerance > 0) m.record_convergence();
  gl::check_errors("a radiance-map frame");
  return accumulate;
}

void RadianceMapRenderer::set_split(int bands, int units_per_call) {
  Impl& m = *impl_;
  if (bands < 1 || units_per_call < 0) throw std::logic_error("set_split: bands >= 1, units >= 0");
  if (bands != m.bands) {
    m.bands = bands;
    m.next_unit = 0;  // a frame begun in other bands starts again
  }
  m.units_per_call = units_per_call;
}

int RadianceMapRenderer::last_call_units() const {
  return impl_->last_call_units;
}

bool RadianceMapRenderer::frame_in_progress() const {
  return impl_->next_unit > 0;
}

int RadianceMapRenderer::accumulated_frames() const {
  return impl_->frame;
}

bool RadianceMapRenderer::converged() const {
  return impl_->frame >= impl_->settings.frames;
}

ImageRgb RadianceMapRenderer::read_image() const {
  const Impl& m = *impl_;
  if (!prepared()) return ImageRgb(m.scene.camera.width, m.scene.camera.height);  // black
  return m.final.read_image();
}

std::vector<std::uint8_t> RadianceMapRenderer::read_mask() const {
  const Impl& m = *impl_;
  if (!prepared())
    return std::vector<std::uint8_t>(std::size_t(m.scene.camera.width) * m.scene.camera.height, 0);
  return m.final.read_mask();
}

void RadianceMapRenderer::present(float exposure, int x, int y, int width, int height) const {
  const Impl& m = *impl_;
  if (!prepared()) return;  // nothing to show yet (the caller cleared the window)
  m.final.present(exposure, x, y, width, height);
}

const RadianceMapStats& RadianceMapRenderer::stats() const {
  return impl_->stats;
}

void RadianceMapRenderer::setup(const Scene& scene, const TechniqueOptions& options) {
  setup(scene, options.settings, options.maps);
}

FrameStats RadianceMapRenderer::frame_stats() const {
  const Impl& m = *impl_;
  const RadianceMapStats& s = m.stats;
  FrameStats f;
  f.frames = accumulated_frames();
  f.pass_ms = {{"light map", s.last_wall.light_map_ms},
               {"radiance map", s.last_wall.radiance_map_ms},
               {"mip blur", s.last_wall.mip_blur_ms},
               {"final", s.last_wall.final_ms}};
  char disc[160];
  if (m.settings.disc_distribution == DiscDistribution::kProfile) {
    std::snprintf(disc, sizeof disc, "disc: the profile's own, R %.3g mm", s.disc_radius_mm);
  } else {
    std::snprintf(disc, sizeof disc, "disc: sigma* %.3g /mm, rho %.3g of R %.3g mm",
                  s.sigma_star_per_mm, s.used_disc_radius_mm, s.disc_radius_mm);
  }
  f.notes.push_back(disc);
  if (s.uncovered_fraction > 0) {
    std::snprintf(disc, sizeof disc, "unseen by every layer: %.1f%% of pixels",
                  100 * s.uncovered_fraction);
    f.notes.push_back(disc);
  }
  return f;
}

void fill_render_stats(const RadianceMapRenderer& renderer, const Scene& scene,
                       const RenderSettings& settings, const RadianceMapOptions& options,
                       double total_ms, RenderStats& stats) {
  const RadianceMapStats& s = renderer.stats();
  const StageTimes wall = s.mean_wall(), gpu = s.mean_gpu();
  stats.technique = "maps";
  stats.width = scene.camera.width;
  stats.height = scene.camera.height;
  stats.total_ms = total_ms;
  stats.pass_ms = {{"setup", s.setup_ms},
                   {"light map", wall.light_map_ms},
                   {"radiance map", wall.radiance_map_ms},
                   {"mip blur", wall.mip_blur_ms},
                   {"final", wall.final_ms}};
  stats.details = {
      {"gl_renderer", s.gl_renderer},
      {"timing", options.time_stages ? "per-frame means, glFinish + wall clock"
                                     : "per-frame means, wall clock without glFinish"},
      {"gpu_query_ms",
       {{"light map", gpu.light_map_ms},
        {"radiance map", gpu.radiance_map_ms},
        {"mip blur", gpu.mip_blur_ms},
        {"final", gpu.final_ms}}},
      {"frames", s.frames},
      {"convergence_frame", s.convergence_frame},
      {"convergence_tolerance", options.convergence_tolerance},
      {"frame_change", s.frame_change},
      {"uncovered_fraction", s.uncovered_fraction},
      // The final pass's quadrature of Jensen's single scattering (single_scattering.glsl).
      {"single_scattering", scene.single_scattering},
      {"single_scattering_steps", scene.single_scattering ? detail::kSingleScatteringSteps : 0},
      {"angular", scene.angular && materials::angular_factor_applies(settings.model)},
      {"geometry_factor",
       scene.geometry_factor && materials::geometry_factor_applies(settings.model)},
      {"sigma_star_per_mm", s.sigma_star_per_mm},
      {"disc_radius_mm", s.disc_radius_mm},
      {"used_disc_radius_mm", s.used_disc_radius_mm},
      {"samples_per_light", s.samples_per_light},
      // What the maps allocate, and Dal Corso's formula for the same K, W_s, L, W_l (Table 5.1).
      {"memory_mib",
       {{"radiance_maps", s.memory.radiance_mib},
        {"radiance_depth", s.memory.radiance_depth_mib},
        {"light_maps", s.memory.light_maps_mib},
        {"total", s.memory.total_mib()},
        {"seed_formula", seed_maps_memory_mib(settings.directions, settings.radiance_map_size,
                                              int(scene.lights.size()), settings.light_map_size)}}},
      {"settings", settings.to_string()},
      {"options", options.to_string()}};
}

ImageRgb render_radiance_maps(const Scene& scene, const RenderSettings& settings,
                              RenderStats* stats) {
  return render_radiance_maps(scene, settings, RadianceMapOptions{}, stats, nullptr);
}

ImageRgb render_radiance_maps(const Scene& scene, const RenderSettings& settings,
                              const RadianceMapOptions& options, RenderStats* stats,
                              RadianceMapStats* details) {
  const double t0 = now_ms();
  const auto context = GlContext::create_headless();
  RadianceMapRenderer renderer;
  renderer.setup(scene, settings, options);
  while (renderer.render_frame()) {
    const int t = renderer.accumulated_frames();
    if (options.on_snapshot &&
        std::find(options.snapshot_frames.begin(), options.snapshot_frames.end(), t) !=
            options.snapshot_frames.end()) {
      options.on_snapshot(t, renderer.read_image());
    }
  }
  ImageRgb image = renderer.read_image();
  if (details != nullptr) *details = renderer.stats();
  if (stats != nullptr)
    fill_render_stats(renderer, scene, settings, options, now_ms() - t0, *stats);
  return image;
}

}  // namespace lucent::render
