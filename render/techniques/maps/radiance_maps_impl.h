// The radiance-map pipeline's internals (radiance_maps.cpp: building and the passes;
// radiance_maps_frame.cpp: the frame-by-frame API): its GL objects, constants and stage timing.
#pragma once

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "area_light.h"
#include "gl_api.h"
#include "gl_area_lights.h"
#include "gl_bssrdf.h"
#include "gl_frame.h"
#include "gl_program.h"
#include "lucent/core/error.h"
#include "lucent/materials/angular.h"
#include "lucent/materials/geometry_factor.h"
#include "lucent/render/environment.h"
#include "lucent/render/gl_context.h"
#include "lucent/render/radiance_maps.h"
#include "radiance_maps_sampling.h"
#include "single_scattering.h"

namespace lucent::render {
namespace maps_detail {

constexpr int kMaxLights = 16;
// Texture units.
constexpr GLuint kUnitLightPositions = 0, kUnitLightNormals = 1, kUnitPrevious = 2,
                 kUnitTabulated = 3, kUnitLightFaceNormals = 4;
constexpr GLuint kUnitRadiance = 0, kUnitRadianceDepth = 1, kUnitEnvironment = 2,
                 kUnitLightPositionsFinal = 3, kUnitLightNormalsFinal = 4,
                 kUnitLightFaceNormalsFinal = 5;
// Uniform-block bindings (as in the shaders).
constexpr GLuint kLightMatricesBinding = 0, kLayerCamerasBinding = 1, kDiscSamplesBinding = 2;

enum Stage { kLightMap, kRadianceMap, kMipBlur, kFinal, kStageCount };

inline double& stage_field(StageTimes& t, int stage) {
  switch (stage) {
    case kLightMap:
      return t.light_map_ms;
    case kRadianceMap:
      return t.radiance_map_ms;
    case kMipBlur:
      return t.mip_blur_ms;
    default:
      return t.final_ms;
  }
}

inline double now_ms() {
  using clock = std::chrono::steady_clock;
  return std::chrono::duration<double, std::milli>(clock::now().time_since_epoch()).count();
}


}  // namespace maps_detail

using namespace maps_detail;

struct RadianceMapRenderer::Impl {
  Scene scene;
  RenderSettings settings;
  RadianceMapOptions options;
  Vec3f centre{0, 0, 0};
  float radius_mm = 1;
  int K = 0, L = 0;

  gl::MeshBuffers mesh;
  gl::VertexArray empty_vao;

  gl::Program light_map_program, radiance_program, blur_program, final_program;
  gl::Program ground_program;  // the ground plane (Scene::ground)

  gl::Buffer light_matrices, layer_cameras, disc_buffer;
  gl::Texture light_positions, light_normals, light_face_normals, light_depth;
  gl::Framebuffer light_fbo;

  std::array<gl::Texture, 2> radiance;
  gl::Texture radiance_depth;
  std::array<gl::Framebuffer, 2> radiance_fbo;
  int levels = 1;
  std::array<std::vector<gl::Texture>, 2> level_views;     // [buffer][l]: level l alone
  std::array<std::vector<gl::Framebuffer>, 2> level_fbos;  // [buffer][l]: draws level l + 1

  gl::Sampler nearest, linear_clamp, mip_nearest, shadow;
  gl::FinalTarget final;       // the image, its environment, background and present pass
  gl::Texture tabulated_rows;  // the tabulated model's three rows (bssrdf_tabulated.glsl)

  std::vector<detail::LayerCamera> layer_cams, light_cams;
  detail::DiscPoints disc_points;  // drawn by upload_lights
  detail::DiscSamples disc;

  std::array<gl::Query, kStageCount> queries;
  int frame = 0;    // accumulated
  int current = 0;  // ping-pong buffer holding the latest sum
  int level = 0;    // blur level of the last final pass
  // A frame split across render_frame calls (set_split): each layer in `bands` bands of rows,
  // `units_per_call` layer-bands a call (0: the whole frame), the next one to render.
  int bands = 1, units_per_call = 0, next_unit = 0, last_call_units = 0;
  bool final_stale = false;  // the camera moved since the last final pass
  bool light_map_valid = false;
  bool programs_have_area_lights = false;  // compiled with LUCENT_AREA_LIGHTS
  std::vector<float> last_image;
  RadianceMapStats stats;
  // The set-up's steps (setup_step): each under ~100 ms on llvmpipe at the viewer's levels.
  enum SetupStage {
    kSetupMeshAndPrograms,
    kSetupLightMaps,
    kSetupRadianceMaps,
    kSetupFinalAndUniforms,
    kSetupDepth,
    kSetupWarmUp,
    kSetupDone
  };
  SetupStage stage = kSetupMeshAndPrograms;
  int depth_layers_done = 0, warm_up_done = 0;

  /// Checks the inputs; the GL set-up follows in setup_step() calls (finish_setup: all of them).
  void build(const Scene& s, const RenderSettings& rs, const RadianceMapOptions& o);
  bool setup_step();  ///< the next step of the set-up; true once it is done
  void finish_setup();
  void upload_mesh();
  void build_programs();
  void build_light_maps();
  void build_radiance_maps();
  void upload_lights();
  void upload_light_cameras(int t);  ///< t: the accumulated frame (area lights' points)
  bool has_area_lights() const {
    return std::any_of(scene.lights.begin(), scene.lights.end(),
                       [](const Light& l) { return l.type == LightType::kArea; });
  }
  void upload_material();
  void upload_disc(int t, bool redraw);
  void upload_layers();
  void render_light_map();
  void render_radiance_depth(int first, int count);  ///< layers [first, first + count)
  /// Layer-bands [first, first + count) of frame t (t % 2 the buffer written; the first clears it).
  void render_radiance(int t, int first, int count);
  void render_blur();
  void render_final();
  void render_ground(const detail::Mat4f& view_proj);
  template <typename F>
  void timed(int stage, F&& work);
  std::vector<float> read_rgba() const;
  void record_convergence();
};

template <typename F>
void RadianceMapRenderer::Impl::timed(int stage, F&& work) {
  if (options.time_stages) glFinish();
  const double t0 = now_ms();
  glBeginQuery(GL_TIME_ELAPSED, queries[std::size_t(stage)].id());
  work();
  glEndQuery(GL_TIME_ELAPSED);
  if (options.time_stages) glFinish();
  const double wall = now_ms() - t0;
  GLuint64 ns = 0;
  glGetQueryObjectui64v(queries[std::size_t(stage)].id(), GL_QUERY_RESULT, &ns);
  stage_field(stats.last_wall, stage) = wall;
  stage_field(stats.sum_wall, stage) += wall;
  stage_field(stats.sum_gpu, stage) += double(ns) * 1e-6;
}

}  // namespace lucent::render
