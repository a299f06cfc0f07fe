// The radiance-map pipeline of Dal Corso 2014 on OpenGL 4.5
// (render/include/lucent/render/radiance_maps.h).
#include "radiance_maps_impl.h"

namespace lucent::render {

void RadianceMapOptions::validate() const {
  if (max_blur_level < -1 || max_blur_level > 8) {
    throw Error("--maps-max-blur: expected -1 (automatic) to 8 levels, got " +
                std::to_string(max_blur_level));
  }
  if (!(shadow_bias_texels >= 0 && shadow_bias_texels <= 64) ||
      !(shrink_texels >= 0 && shrink_texels <= 64)) {
    throw Error("radiance maps: the shadow bias and shrink must be 0..64 texels");
  }
  if (!(convergence_tolerance > 0 && convergence_tolerance < 1)) {
    throw Error("radiance maps: the convergence tolerance must be in (0, 1)");
  }
  for (int t : snapshot_frames)
    if (t < 1) throw Error("--snapshots: frames must be at least 1, got " + std::to_string(t));
}

std::string RadianceMapOptions::to_string() const {
  std::ostringstream s;
  s << "RadianceMapOptions{max_blur_level=" << max_blur_level
    << ", layer_weights=" << (cos_weighted_layers ? "cos" : "equal")
    << ", shadow_bias_texels=" << shadow_bias_texels << ", shrink_texels=" << shrink_texels
    << ", new_radii_each_frame=" << new_radii_each_frame
    << ", convergence_tolerance=" << convergence_tolerance << ", time_stages=" << time_stages
    << ", environment_reflection=" << environment_reflection << "}";
  return s.str();
}

namespace {

// Per-stage means: the light map is rendered once per restart, the final pass once per displayed
// frame, the other stages once per accumulated frame.
StageTimes mean_of(StageTimes sum, int frames, int light_map_renders, int frames_rendered) {
  const double f = std::max(frames, 1);
  sum.light_map_ms /= std::max(light_map_renders, 1);
  sum.radiance_map_ms /= f;
  sum.mip_blur_ms /= f;
  sum.final_ms /= std::max(frames_rendered, 1);
  return sum;
}

}  // namespace

StageTimes RadianceMapStats::mean_wall() const {
  return mean_of(sum_wall, frames, light_map_renders, frames_rendered);
}

StageTimes RadianceMapStats::mean_gpu() const {
  return mean_of(sum_gpu, frames, light_map_renders, frames_rendered);
}

std::string RadianceMapStats::to_string() const {
  const StageTimes w = mean_wall(), g = mean_gpu();
  std::ostringstream s;
  s.precision(4);
  s << "RadianceMapStats{" << gl_renderer << "; frames=" << frames
    << ", convergence_frame=" << convergence_frame << ", setup=" << setup_ms
    << "ms; per frame (glFinish + wall clock): light map " << w.light_map_ms << "ms, radiance map "
    << w.radiance_map_ms << "ms, mip blur " << w.mip_blur_ms << "ms, final " << w.final_ms
    << "ms; GL_TIME_ELAPSED: " << g.light_map_ms << ", " << g.radiance_map_ms << ", "
    << g.mip_blur_ms << ", " << g.final_ms << "ms; uncovered " << uncovered_fraction
    << "; sigma*=" << sigma_star_per_mm << "/mm, R=" << disc_radius_mm
    << "mm, rho=" << used_disc_radius_mm << "mm, N/L=" << samples_per_light << "}";
  return s.str();
}

int radiance_map_levels(const RenderSettings& settings, int max_blur_level) {
  if (max_blur_level < 0) {
    max_blur_level = settings.disc_distribution == DiscDistribution::kProfile ? 0 : 2;
  }
  int levels = 1;
  while (levels <= max_blur_level && (settings.radiance_map_size >> levels) >= 1) ++levels;
  return levels;
}

MapsMemory maps_memory(const RenderSettings& s, int lights, int mip_levels) {
  constexpr double kMiB = 1024.0 * 1024.0;
  const double layer = double(s.radiance_map_size) * s.radiance_map_size;
  double mips = 0;  // texels of a layer's levels over its full size
  for (int l = 0; l < mip_levels; ++l) mips += std::pow(0.25, l);
  MapsMemory m;
  m.radiance_mib = 2 * s.directions * layer * 16 * mips / kMiB;
  m.radiance_depth_mib = s.directions * layer * 4 / kMiB;
  m.light_maps_mib =
      double(lights) * s.light_map_size * s.light_map_size * (16 + 16 + 8 + 4) / kMiB;
  return m;
}

double seed_maps_memory_mib(int directions, int radiance_map_size, int lights, int light_map_size) {
  const double ws2 = double(radiance_map_size) * radiance_map_size;
  const double wl2 = double(light_map_size) * light_map_size;
  return 4 * ((8.0 * 4.0 / 3.0 + 1) * directions * ws2 + 7.0 * lights * wl2) / (1024.0 * 1024.0);
}

RadianceMapRenderer::RadianceMapRenderer() : impl_(std::make_unique<Impl>()) {}
RadianceMapRenderer::~RadianceMapRenderer() = default;

void RadianceMapRenderer::setup(const Scene& scene, const RenderSettings& settings,
                                const RadianceMapOptions& options) {
  impl_ = std::make_unique<Impl>();
  impl_->build(scene, settings, options);
  if (!options.staged_setup) impl_->finish_setup();
}

bool RadianceMapRenderer::prepare_step() {
  return impl_->setup_step();
}

bool RadianceMapRenderer::prepared() const {
  return impl_->stage == Impl::kSetupDone;
}

void RadianceMapRenderer::Impl::build(const Scene& s, const RenderSettings& rs,
                                      const RadianceMapOptions& o) {
  scene = s;
  settings = rs;
  options = o;
  settings.validate();
  if (scene.mesh.positions.empty() || scene.mesh.triangles.empty()) {
    throw Error("radiance maps: the mesh '" + scene.mesh.name + "' is empty");
  }
  if (scene.mesh.normals.size() != scene.mesh.positions.size()) {
    throw Error("radiance maps: the mesh '" + scene.mesh.name + "' has no per-vertex normals");
  }
  if (scene.lights.empty()) throw Error("--light: the radiance maps need at least one light");
  if (int(scene.lights.size()) > kMaxLights) {
    throw Error("--light: the radiance maps take at most " + std::to_string(kMaxLights) +
                " lights, got " + std::to_string(scene.lights.size()));
  }
  options.validate();
  if (options.max_blur_level < 0) {
    options.max_blur_level = settings.disc_distribution == DiscDistribution::kProfile ? 0 : 2;
  }
  stats.memory = maps_memory(settings, int(scene.lights.size()),
                             radiance_map_levels(settings, options.max_blur_level));
  K = settings.directions;
  L = int(scene.lights.size());
  GLint max_block = 0;
  glGetIntegerv(GL_MAX_UNIFORM_BLOCK_SIZE, &max_block);
  if (K * 80 > max_block) {
    throw Error("--maps-directions: this OpenGL allows at most " + std::to_string(max_block / 80) +
                " radiance-map directions, got " + std::to_string(K));
  }
  if (settings.samples * 16 > max_block) {
    throw Error("--maps-samples: this OpenGL allows at most " + std::to_string(max_block / 16) +
                " disc samples, got " + std::to_string(settings.samples));
  }
  centre = scene.mesh.centre();
  radius_mm = scene.mesh.bounding_radius();
  stats.gl_renderer = std::string(reinterpret_cast<const char*>(glGetString(GL_RENDERER))) + " | " +
                      reinterpret_cast<const char*>(glGetString(GL_VERSION));

  stage = kSetupMeshAndPrograms;
}

bool RadianceMapRenderer::Impl::setup_step() {
  if (stage == kSetupDone) return true;
  const double t0 = now_ms();
  switch (stage) {
    case kSetupMeshAndPrograms:
      upload_mesh();
      build_programs();
      stage = kSetupLightMaps;
      break;
    case kSetupLightMaps:
      build_light_maps();
      stage = kSetupRadianceMaps;
      break;
    case kSetupRadianceMaps:
      build_radiance_maps();
      stage = kSetupFinalAndUniforms;
      break;
    case kSetupFinalAndUniforms:
      final.build(scene, scene.camera.width, scene.camera.height, kUnitEnvironment);
      upload_layers();
      upload_material();  // and the lights with it (the disc depends on both)
      for (auto& q : queries) q = gl::create_query(GL_TIME_ELAPSED);
      stage = kSetupDepth;
      break;
    case kSetupDepth: {
      // The depth pre-pass: whole, or staged in four runs of layers.
      const int count = options.staged_setup ? (K + 3) / 4 : K;
      render_radiance_depth(depth_layers_done, std::min(count, K - depth_layers_done));
      glFinish();
      stats.depth_pass_ms += now_ms() - t0;  // a lower bound on a radiance pass (same geometry)
      depth_layers_done += count;
      if (depth_layers_done >= K) stage = kSetupWarmUp;
      break;
    }
    case kSetupWarmUp:
      // One untimed pass of every program, so that drivers that compile shaders at their first
      // draw (llvmpipe's JIT, 60-100 ms a program there even from its disk cache; most GPU
      // drivers) do it here and not inside the first frame (seed §6.3 likewise leaves the first
      // frames out of its timings). A step a program; the gather on one layer's band only (frame
      // 1's first call clears what it wrote).
      if (warm_up_done == 0) {
        render_light_map();
      } else if (warm_up_done == 1) {
        render_radiance(1, 0, 1);
        glFinish();
        stats.warm_up_layer_ms = (now_ms() - t0) * bands;
      } else {
        level = levels - 1;
        render_blur();
        level = 0;
        const double f0 = now_ms();
        render_final();
        glFinish();
        stats.warm_up_final_ms = now_ms() - f0;
        stage = kSetupDone;
      }
      ++warm_up_done;
      break;
    case kSetupDone:
      break;
  }
  glFinish();  // the step's work inside its own wall clock (and its caller's frame)
  gl::check_errors("radiance-map setup");
  stats.setup_ms += now_ms() - t0;
  return stage == kSetupDone;
}

void RadianceMapRenderer::Impl::finish_setup() {
  while (!setup_step()) {
  }
}

void RadianceMapRenderer::Impl::upload_mesh() {
  mesh = gl::upload_mesh(scene.mesh);
  empty_vao = gl::create_vertex_array();
}

void RadianceMapRenderer::Impl::build_programs() {
  programs_have_area_lights = gl::has_area_lights(scene.lights);
  std::vector<std::string> defines = {
      "LUCENT_MAX_LIGHTS " + std::to_string(kMaxLights),
      "LUCENT_MAX_DIRECTIONS " + std::to_string(K),
      "LUCENT_MAX_DISC_SAMPLES " + std::to_string(settings.samples),
      settings.model == DiffusionModel::kDipole      ? "LUCENT_MODEL_DIPOLE"
      : settings.model == DiffusionModel::kTabulated ? "LUCENT_MODEL_TABULATED"
                                                     : "LUCENT_MODEL_DDIPOLE"};
  for (const std::string& d : gl::area_light_defines(scene.lights)) defines.push_back(d);
  light_map_program = gl::Program({{GL_VERTEX_SHADER, "layered_mesh.vert"},
                                   {GL_GEOMETRY_SHADER, "light_map.geom"},
                                   {GL_FRAGMENT_SHADER, "light_map.frag"}},
                                  defines);
  radiance_program = gl::Program({{GL_VERTEX_SHADER, "layered_mesh.vert"},
                                  {GL_GEOMETRY_SHADER, "radiance_map.geom"},
                                  {GL_FRAGMENT_SHADER, "radiance_map.frag"}},
                                 defines);
  blur_program = gl::Program({{GL_VERTEX_SHADER, "fullscreen_layers.vert"},
                              {GL_GEOMETRY_SHADER, "mip_blur.geom"},
                              {GL_FRAGMENT_SHADER, "mip_blur.frag"}},
                             defines);
  final_program =
      gl::Program({{GL_VERTEX_SHADER, "final.vert"}, {GL_FRAGMENT_SHADER, "final.frag"}}, defines);
  if (scene.ground) {
    ground_program = gl::Program(
        {{GL_VERTEX_SHADER, "ground.vert"}, {GL_FRAGMENT_SHADER, "ground.frag"}}, defines);
  }

  const auto unit = [](const gl::Program& p, const char* name, GLint u) {
    glProgramUniform1i(p.id(), p.location(name), u);
  };
  unit(radiance_program, "u_light_positions", kUnitLightPositions);
  unit(radiance_program, "u_light_normals", kUnitLightNormals);
  unit(radiance_program, "u_light_face_normals", kUnitLightFaceNormals);
  unit(radiance_program, "u_previous", kUnitPrevious);
  unit(blur_program, "u_source", 0);
  unit(final_program, "u_radiance", kUnitRadiance);
  unit(final_program, "u_radiance_depth", kUnitRadianceDepth);
  unit(final_program, "u_environment", kUnitEnvironment);
  unit(final_program, "u_light_positions", kUnitLightPositionsFinal);
  unit(final_program, "u_light_normals", kUnitLightNormalsFinal);
  unit(final_program, "u_light_face_normals", kUnitLightFaceNormalsFinal);

  // One sampler object per way of reading: filters and wrap modes.
  const auto sampler = [](GLint min_filter, GLint mag_filter, GLint wrap_s) {
    gl::Sampler s = gl::create_sampler();
    glSamplerParameteri(s.id(), GL_TEXTURE_MIN_FILTER, min_filter);
    glSamplerParameteri(s.id(), GL_TEXTURE_MAG_FILTER, mag_filter);
    glSamplerParameteri(s.id(), GL_TEXTURE_WRAP_S, wrap_s);
    glSamplerParameteri(s.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return s;
  };
  nearest = sampler(GL_NEAREST, GL_NEAREST, GL_CLAMP_TO_EDGE);
  linear_clamp = sampler(GL_LINEAR, GL_LINEAR, GL_CLAMP_TO_EDGE);
  // The final pass reads one whole level (u_mip_level is an integer): bilinear within it.
  mip_nearest = sampler(GL_LINEAR_MIPMAP_NEAREST, GL_LINEAR, GL_CLAMP_TO_EDGE);
  // Seed Listing 5.9: compare against the stored depth; nearest, as the seed.
  shadow = sampler(GL_NEAREST, GL_NEAREST, GL_CLAMP_TO_EDGE);
  glSamplerParameteri(shadow.id(), GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glSamplerParameteri(shadow.id(), GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
}

void RadianceMapRenderer::Impl::build_light_maps() {
  const int W = settings.light_map_size;
  light_positions = gl::create_texture(GL_TEXTURE_2D_ARRAY);
  light_normals = gl::create_texture(GL_TEXTURE_2D_ARRAY);
  light_face_normals = gl::create_texture(GL_TEXTURE_2D_ARRAY);
  light_depth = gl::create_texture(GL_TEXTURE_2D_ARRAY);
  glTextureStorage3D(light_positions.id(), 1, GL_RGBA32F, W, W, L);
  glTextureStorage3D(light_normals.id(), 1, GL_RGBA32F, W, W, L);
  glTextureStorage3D(light_face_normals.id(), 1, GL_RGBA16F, W, W, L);
  glTextureStorage3D(light_depth.id(), 1, GL_DEPTH_COMPONENT32F, W, W, L);
  light_fbo = gl::create_framebuffer();
  glNamedFramebufferTexture(light_fbo.id(), GL_COLOR_ATTACHMENT0, light_positions.id(), 0);
  glNamedFramebufferTexture(light_fbo.id(), GL_COLOR_ATTACHMENT1, light_normals.id(), 0);
  glNamedFramebufferTexture(light_fbo.id(), GL_COLOR_ATTACHMENT2, light_face_normals.id(), 0);
  glNamedFramebufferTexture(light_fbo.id(), GL_DEPTH_ATTACHMENT, light_depth.id(), 0);
  const GLenum buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
  glNamedFramebufferDrawBuffers(light_fbo.id(), 3, buffers);
  gl::check_framebuffer(light_fbo.id(), "the light map");
  light_matrices = gl::create_buffer();
  glNamedBufferStorage(light_matrices.id(), kMaxLights * sizeof(detail::Mat4f), nullptr,
                       GL_DYNAMIC_STORAGE_BIT);
}

void RadianceMapRenderer::Impl::build_radiance_maps() {
  const int W = settings.radiance_map_size;
  levels = radiance_map_levels(settings, options.max_blur_level);
  radiance_depth = gl::create_texture(GL_TEXTURE_2D_ARRAY);
  glTextureStorage3D(radiance_depth.id(), 1, GL_DEPTH_COMPONENT32F, W, W, K);
  for (int b = 0; b < 2; ++b) {
    radiance[b] = gl::create_texture(GL_TEXTURE_2D_ARRAY);
    glTextureStorage3D(radiance[b].id(), levels, GL_RGBA32F, W, W, K);
    radiance_fbo[b] = gl::create_framebuffer();
    // Both ping-pong buffers share one depth array (seed §5.3.6): the geometry does not change.
    glNamedFramebufferTexture(radiance_fbo[b].id(), GL_COLOR_ATTACHMENT0, radiance[b].id(), 0);
    glNamedFramebufferTexture(radiance_fbo[b].id(), GL_DEPTH_ATTACHMENT, radiance_depth.id(), 0);
    gl::check_framebuffer(radiance_fbo[b].id(), "the radiance maps");
    level_views[b].clear();
    level_fbos[b].clear();
    for (int l = 0; l + 1 < levels; ++l) {
      // A view of level l alone to sample while level l + 1 of the same storage is drawn (GL
      // forbids sampling a texture bound for drawing, whatever the levels; seed §5.4.2).
      GLuint view = 0;
      glGenTextures(1, &view);
      glTextureView(view, GL_TEXTURE_2D_ARRAY, radiance[b].id(), GL_RGBA32F, GLuint(l), 1, 0,
                    GLuint(K));
      level_views[b].emplace_back(view);
      gl::Framebuffer fbo = gl::create_framebuffer();
      glNamedFramebufferTexture(fbo.id(), GL_COLOR_ATTACHMENT0, radiance[b].id(), l + 1);
      gl::check_framebuffer(fbo.id(), "a radiance-map mip level");
      level_fbos[b].push_back(std::move(fbo));
    }
  }
  layer_cameras = gl::create_buffer();
  glNamedBufferStorage(layer_cameras.id(), GLsizeiptr(K * 80), nullptr, GL_DYNAMIC_STORAGE_BIT);
  disc_buffer = gl::create_buffer();
  glNamedBufferStorage(disc_buffer.id(), GLsizeiptr(settings.samples * 16), nullptr,
                       GL_DYNAMIC_STORAGE_BIT);
}

void RadianceMapRenderer::Impl::upload_layers() {
  const std::vector<Vec3f> directions = detail::halton_sphere_directions(K);
  layer_cams.clear();
  std::vector<float> block(std::size_t(K) * 20, 0.0f);
  for (int k = 0; k < K; ++k) {
    layer_cams.push_back(detail::fitted_orthographic(centre, radius_mm, directions[k]));
    std::copy_n(layer_cams[k].view_proj.data(), 16, &block[std::size_t(k) * 16]);
    const Vec3f& d = layer_cams[k].direction;
    float* v = &block[std::size_t(K) * 16 + std::size_t(k) * 4];
    v[0] = d.x();
    v[1] = d.y();
    v[2] = d.z();
  }
  glNamedBufferSubData(layer_cameras.id(), 0, GLsizeiptr(block.size() * sizeof(float)),
                       block.data());
}

void RadianceMapRenderer::Impl::upload_lights() {
  L = int(scene.lights.size());
  upload_light_cameras(1);
  gl::upload_area_lights(radiance_program.id(), scene.lights);
  gl::upload_area_lights(final_program.id(), scene.lights);
  upload_disc(1, true);
}

void RadianceMapRenderer::Impl::upload_light_cameras(int t) {
  light_cams.clear();
  std::vector<float> matrices(std::size_t(kMaxLights) * 16, 0.0f);
  std::vector<float> position(std::size_t(kMaxLights) * 4, 0.0f),
      radiance_(std::size_t(kMaxLights) * 3, 0.0f), texel(std::size_t(kMaxLights) * 2, 0.0f);
  for (int l = 0; l < L; ++l) {
    const Light& light = scene.lights[std::size_t(l)];
    if (light.type == LightType::kArea) {
      // Frame t's light map is the view from one point of the polygon (gl_area_lights.h); the
      // radiance pass weights what it sees with the exact form factor (radiance_map.frag).
      const Vec3f s = gl::area_light_frame_point(light, std::size_t(l), t);
      light_cams.push_back(detail::fitted_area_perspective(centre, radius_mm, s,
                                                           area_light_normal(light)));
      for (int c = 0; c < 3; ++c) position[std::size_t(l) * 4 + std::size_t(c)] = s[c];
      position[std::size_t(l) * 4 + 3] = float(2 + gl::area_slot(scene.lights, std::size_t(l)));
    } else if (light.type == LightType::kDirectional) {
      const Vec3f d = light.direction.normalized();
      light_cams.push_back(detail::fitted_orthographic(centre, radius_mm, d));
      position[std::size_t(l) * 4 + 0] = d.x();
      position[std::size_t(l) * 4 + 1] = d.y();
      position[std::size_t(l) * 4 + 2] = d.z();
      position[std::size_t(l) * 4 + 3] = 0;
    } else {
      light_cams.push_back(detail::fitted_perspective(centre, radius_mm, light.position));
      for (int c = 0; c < 3; ++c) position[std::size_t(l) * 4 + std::size_t(c)] = light.position[c];
      position[std::size_t(l) * 4 + 3] = 1;
    }
    for (int c = 0; c < 3; ++c) radiance_[std::size_t(l) * 3 + std::size_t(c)] = light.radiance[c];
    std::copy_n(light_cams.back().view_proj.data(), 16, &matrices[std::size_t(l) * 16]);
    texel[std::size_t(l) * 2] = light_cams.back().extent_mm / float(settings.light_map_size);
    texel[std::size_t(l) * 2 + 1] = light_cams.back().extent_per_mm / float(settings.light_map_size);
  }
  glNamedBufferSubData(light_matrices.id(), 0, GLsizeiptr(matrices.size() * sizeof(float)),
                       matrices.data());
  // The same light uniforms in every program that shades with the lights (the ground has no
  // texel size: it filters the light map's visibility only).
  for (const gl::Program* program : {&radiance_program, &final_program, &ground_program}) {
    if (program->id() == 0) continue;  // no ground
    const GLuint id = program->id();
    glProgramUniform1i(id, program->location("u_light_count"), L);
    glProgramUniform4fv(id, program->location("u_light_position"), kMaxLights, position.data());
    glProgramUniform3fv(id, program->location("u_light_radiance"), kMaxLights, radiance_.data());
    if (program != &ground_program) {
      glProgramUniform2fv(id, program->location("u_light_texel_mm"), kMaxLights, texel.data());
    }
  }
}

void RadianceMapRenderer::Impl::upload_disc(int t, bool redraw) {
  // The disc: radius of the mesh's bounding box diagonal (seed §5.3.4.1: "a radius equal to the
  // size of the bounding box"), shared round-robin by the lights.
  // Drawing the M points is the costly part (tens of ms): only when the material, mesh or lights
  // changed (upload_lights) or when every frame has new radii.
  if (redraw || options.new_radii_each_frame) {
    const double box = (scene.mesh.bounds_max() - scene.mesh.bounds_min()).norm();
    const Eigen::Vector3d shift =
        options.new_radii_each_frame ? detail::frame_shift(t) : Eigen::Vector3d::Zero();
    disc_points = settings.disc_distribution == DiscDistribution::kProfile
                      ? detail::profile_disc_points(settings.disc_points, scene.material,
                                                    settings.model, box, shift)
                      : detail::exponential_disc_points(
                            settings.disc_points, detail::sigma_star(scene.material, settings.q),
                            box, shift);
  }
  disc = detail::select_disc_samples(disc_points, settings.samples, L, settings.disc_selection, t);
  std::vector<float> packed(std::size_t(settings.samples) * 4, 0.0f);
  for (std::size_t i = 0; i < disc.samples.size(); ++i) {
    packed[i * 4 + 0] = disc.samples[i].x_mm;
    packed[i * 4 + 1] = disc.samples[i].y_mm;
    packed[i * 4 + 2] = disc.samples[i].weight_mm2;
  }
  glNamedBufferSubData(disc_buffer.id(), 0, GLsizeiptr(packed.size() * sizeof(float)),
                       packed.data());
  std::vector<GLint> offset(kMaxLights, 0), count(kMaxLights, 0);
  for (int l = 0; l < L; ++l) {
    offset[std::size_t(l)] = disc.light_offset[std::size_t(l)];
    count[std::size_t(l)] = disc.light_count[std::size_t(l)];
  }
  const GLuint p = radiance_program.id();
  glProgramUniform1iv(p, radiance_program.location("u_light_sample_offset"), kMaxLights,
                      offset.data());
  glProgramUniform1iv(p, radiance_program.location("u_light_sample_count"), kMaxLights,
                      count.data());
  stats.sigma_star_per_mm = disc.sigma_star_per_mm;
  stats.disc_radius_mm = disc.disc_radius_mm;
  stats.used_disc_radius_mm = disc.used_radius_mm;
  stats.samples_per_light = disc.light_count.empty() ? 0 : disc.light_count[0];
}

void RadianceMapRenderer::Impl::upload_material() {
  gl::set_bssrdf_uniforms(radiance_program.id(), scene.material);
  const bool angular = scene.angular && materials::angular_factor_applies(settings.model);
  gl::set_angular_uniforms(radiance_program.id(), scene.material, angular, scene.oblique_skew);
  gl::set_angular_uniforms(final_program.id(), scene.material, angular, scene.oblique_skew);
  gl::set_geometry_factor_uniforms(
      radiance_program.id(), scene.material,
      scene.geometry_factor && materials::geometry_factor_applies(settings.model));
  gl::set_fur_coat_uniforms(radiance_program.id(), scene.fur_coat);
  gl::set_fur_coat_uniforms(final_program.id(), scene.fur_coat);  // the specular lobe's light
  if (settings.model == DiffusionModel::kTabulated) {
    gl::set_tabulated(radiance_program.id(), scene.material, kUnitTabulated, tabulated_rows);
  }
  const GLuint f = final_program.id();
  glProgramUniform1f(f, final_program.location("u_eta"), float(scene.material.ior));
  const detail::SingleMedium single = detail::SingleMedium::of(scene.material);
  const auto vec3 = [&](const char* name, const std::array<double, 3>& v) {
    glProgramUniform3f(f, final_program.location(name), float(v[0]), float(v[1]), float(v[2]));
  };
  vec3("u_single_sigma_s", single.sigma_s);
  vec3("u_single_sigma_t", single.sigma_t);
  vec3("u_single_g", single.g);
  glProgramUniform1i(f, final_program.location("u_single_steps"), detail::kSingleScatteringSteps);
  // sigma* depends on the material: the disc is rebuilt with the lights.
  upload_lights();
}

}  // namespace lucent::render
