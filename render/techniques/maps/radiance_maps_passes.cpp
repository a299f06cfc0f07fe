// The radiance maps' render passes (radiance_maps.h, DESIGN §7.1): the light maps, the depth
// pre-pass, the radiance gather, the mip blur, the final pass and the ground.
#include "radiance_maps_impl.h"

namespace lucent::render {

void RadianceMapRenderer::Impl::render_light_map() {
  const int W = settings.light_map_size;
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, light_fbo.id());
  glViewport(0, 0, W, W);
  const float zero[4] = {0, 0, 0, 0};
  const float one = 1.0f;
  glClearNamedFramebufferfv(light_fbo.id(), GL_COLOR, 0, zero);
  glClearNamedFramebufferfv(light_fbo.id(), GL_COLOR, 1, zero);
  glClearNamedFramebufferfv(light_fbo.id(), GL_COLOR, 2, zero);
  glClearNamedFramebufferfv(light_fbo.id(), GL_DEPTH, 0, &one);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
  light_map_program.use();
  glBindBufferBase(GL_UNIFORM_BUFFER, kLightMatricesBinding, light_matrices.id());
  mesh.draw_instanced(L);
}

void RadianceMapRenderer::Impl::render_radiance_depth(int first, int count) {
  // Depth pre-pass into the shared depth array, once: the radiance pass then tests GL_LEQUAL with
  // early fragment tests, so only the surface each texel sees runs the expensive gather.
  const int W = settings.radiance_map_size;
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, radiance_fbo[0].id());
  glViewport(0, 0, W, W);
  const float one = 1.0f;
  if (first == 0) glClearNamedFramebufferfv(radiance_fbo[0].id(), GL_DEPTH, 0, &one);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  radiance_program.use();
  const GLuint p = radiance_program.id();
  glProgramUniform1i(p, radiance_program.location("u_depth_only"), 1);
  glProgramUniform1i(p, radiance_program.location("u_first_layer"), first);
  glBindBufferBase(GL_UNIFORM_BUFFER, kLayerCamerasBinding, layer_cameras.id());
  mesh.draw_instanced(count);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glProgramUniform1i(p, radiance_program.location("u_depth_only"), 0);
  glProgramUniform1i(p, radiance_program.location("u_first_layer"), 0);
}

void RadianceMapRenderer::Impl::render_radiance(int t, int first, int count) {
  // Frame t (1-based) writes buffer t % 2 and reads the sum so far from the other (seed §5.3.3).
  const int target = t % 2, previous = 1 - target;
  const int W = settings.radiance_map_size;
  if (first == 0) {
    if (options.new_radii_each_frame || settings.disc_selection == DiscSelection::kStrata) {
      upload_disc(t, false);
    }
    const float zero[4] = {0, 0, 0, 0};
    glClearNamedFramebufferfv(radiance_fbo[target].id(), GL_COLOR, 0, zero);
  }
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, radiance_fbo[target].id());
  glViewport(0, 0, W, W);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  glDepthMask(GL_FALSE);
  radiance_program.use();
  const GLuint p = radiance_program.id();
  glProgramUniform1i(p, radiance_program.location("u_has_previous"), t > 1 ? 1 : 0);
  glProgramUniform1f(p, radiance_program.location("u_rotation_offset"),
                     float(t - 1) / float(settings.frames));
  glBindBufferBase(GL_UNIFORM_BUFFER, kLightMatricesBinding, light_matrices.id());
  glBindBufferBase(GL_UNIFORM_BUFFER, kLayerCamerasBinding, layer_cameras.id());
  glBindBufferBase(GL_UNIFORM_BUFFER, kDiscSamplesBinding, disc_buffer.id());
  glBindTextureUnit(kUnitLightPositions, light_positions.id());
  glBindSampler(kUnitLightPositions, nearest.id());
  glBindTextureUnit(kUnitLightNormals, light_normals.id());
  glBindSampler(kUnitLightNormals, nearest.id());
  glBindTextureUnit(kUnitLightFaceNormals, light_face_normals.id());
  glBindSampler(kUnitLightFaceNormals, nearest.id());
  glBindTextureUnit(kUnitPrevious, radiance[previous].id());
  glBindSampler(kUnitPrevious, nearest.id());
  if (settings.model == DiffusionModel::kTabulated) {
    glBindTextureUnit(kUnitTabulated, tabulated_rows.id());
    glBindSampler(kUnitTabulated, nearest.id());
  }
  const GLint first_layer = radiance_program.location("u_first_layer");
  if (bands == 1) {
    glProgramUniform1i(p, first_layer, first);  // a run of whole layers, one instanced draw
    mesh.draw_instanced(count);
  } else {
    // One layer at a time, its rows in bands: the rasteriser skips what the scissor leaves out.
    glEnable(GL_SCISSOR_TEST);
    for (int u = first; u < first + count; ++u) {
      const int band = u % bands, y0 = band * W / bands, y1 = (band + 1) * W / bands;
      glScissor(0, y0, W, y1 - y0);
      glProgramUniform1i(p, first_layer, u / bands);
      mesh.draw_instanced(1);
    }
    glDisable(GL_SCISSOR_TEST);
  }
  glProgramUniform1i(p, first_layer, 0);
  glDepthMask(GL_TRUE);
}

void RadianceMapRenderer::Impl::render_blur() {
  glDisable(GL_DEPTH_TEST);
  blur_program.use();
  glBindVertexArray(empty_vao.id());
  const int W = settings.radiance_map_size;
  for (int l = 0; l < level; ++l) {
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, level_fbos[current][std::size_t(l)].id());
    glViewport(0, 0, std::max(W >> (l + 1), 1), std::max(W >> (l + 1), 1));
    glBindTextureUnit(0, level_views[current][std::size_t(l)].id());
    glBindSampler(0, linear_clamp.id());
    glDrawArraysInstanced(GL_TRIANGLES, 0, 3, K);
  }
}

void RadianceMapRenderer::Impl::render_final() {
  final_stale = false;
  const detail::Mat4f view_proj = detail::camera_view_proj(scene.camera, centre, radius_mm);
  final.begin_frame(view_proj, scene.backdrop);
  if (scene.ground) render_ground(view_proj);

  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  final_program.use();
  const float texel_mm = 2.0f * radius_mm * 1.02f / float(settings.radiance_map_size);
  const detail::LayerCamera& any_layer = layer_cams.front();
  glUniformMatrix4fv(final_program.location("u_view_proj"), 1, GL_FALSE, view_proj.data());
  glUniform1i(final_program.location("u_layer_count"), K);
  glUniform1f(final_program.location("u_mip_level"), float(level));
  glUniform1f(final_program.location("u_depth_bias_mm"), options.shadow_bias_texels * texel_mm);
  glUniform1f(final_program.location("u_texel_mm"), texel_mm);
  glUniform1f(final_program.location("u_depth_range_mm"), any_layer.far_mm - any_layer.near_mm);
  glUniform1f(final_program.location("u_shrink_mm"), options.shrink_texels * texel_mm);
  glUniform1i(final_program.location("u_cos_weighted_layers"), options.cos_weighted_layers ? 1 : 0);
  glUniform3fv(final_program.location("u_eye"), 1, scene.camera.eye.data());
  glUniform1i(final_program.location("u_has_environment"),
              final.has_environment() && options.environment_reflection ? 1 : 0);
  glUniform1f(final_program.location("u_roughness"), scene.roughness);
  glUniform1i(final_program.location("u_specular"), scene.specular ? 1 : 0);
  glUniform1i(final_program.location("u_single_scattering"), scene.single_scattering ? 1 : 0);
  glBindBufferBase(GL_UNIFORM_BUFFER, kLayerCamerasBinding, layer_cameras.id());
  glBindBufferBase(GL_UNIFORM_BUFFER, kLightMatricesBinding, light_matrices.id());
  glBindTextureUnit(kUnitLightPositionsFinal, light_positions.id());
  glBindSampler(kUnitLightPositionsFinal, nearest.id());
  glBindTextureUnit(kUnitLightNormalsFinal, light_normals.id());
  glBindSampler(kUnitLightNormalsFinal, nearest.id());
  glBindTextureUnit(kUnitLightFaceNormalsFinal, light_face_normals.id());
  glBindSampler(kUnitLightFaceNormalsFinal, nearest.id());
  glBindTextureUnit(kUnitRadiance, radiance[current].id());
  glBindSampler(kUnitRadiance, mip_nearest.id());
  glBindTextureUnit(kUnitRadianceDepth, radiance_depth.id());
  glBindSampler(kUnitRadianceDepth, shadow.id());
  mesh.draw();
}

// The ground under the object (ground.frag), drawn after the background and before the object. With
// the eye above the plane no ray to the object crosses the ground, so it needs no depth test; depth
// clamping keeps it beyond the far plane (the camera's depth range is the object's).
void RadianceMapRenderer::Impl::render_ground(const detail::Mat4f& view_proj) {
  const float floor_mm = scene.mesh.bounds_min().y();
  if (scene.camera.eye.y() <= floor_mm) return;  // seen from below: no ground
  ground_program.use();
  const Vec3f ground_centre(centre.x(), floor_mm, centre.z());
  glUniformMatrix4fv(ground_program.location("u_view_proj"), 1, GL_FALSE, view_proj.data());
  glUniform3fv(ground_program.location("u_ground_centre"), 1, ground_centre.data());
  glUniform1f(ground_program.location("u_ground_half_mm"), 6 * radius_mm);
  glUniform1f(ground_program.location("u_object_radius_mm"), radius_mm);
  glUniform3fv(ground_program.location("u_ground_albedo"), 1, scene.ground->data());
  glUniform1i(ground_program.location("u_light_positions"), kUnitLightPositionsFinal);
  glBindBufferBase(GL_UNIFORM_BUFFER, kLightMatricesBinding, light_matrices.id());
  glBindTextureUnit(kUnitLightPositionsFinal, light_positions.id());
  glBindSampler(kUnitLightPositionsFinal, nearest.id());
  glDisable(GL_DEPTH_TEST);
  glDepthMask(GL_FALSE);
  glEnable(GL_DEPTH_CLAMP);
  glBindVertexArray(empty_vao.id());
  glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
  glDisable(GL_DEPTH_CLAMP);
  glDepthMask(GL_TRUE);
}

std::vector<float> RadianceMapRenderer::Impl::read_rgba() const {
  return final.read_rgba();
}

void RadianceMapRenderer::Impl::record_convergence() {
  const std::vector<float> rgba = read_rgba();
  std::size_t object = 0, uncovered = 0;
  for (std::size_t i = 0; i < rgba.size(); i += 4) {
    object += rgba[i + 3] > 0;
    uncovered += rgba[i + 3] > 0 && rgba[i + 3] < 1;
  }
  stats.uncovered_fraction = object > 0 ? double(uncovered) / double(object) : 0.0;
  if (!last_image.empty()) {
    double diff = 0, norm = 0;
    for (std::size_t i = 0; i < rgba.size(); i += 4) {
      if (!(rgba[i + 3] > 0)) continue;
      for (int c = 0; c < 3; ++c) {
        const double d = double(rgba[i + std::size_t(c)]) - last_image[i + std::size_t(c)];
        diff += d * d;
        norm += double(rgba[i + std::size_t(c)]) * rgba[i + std::size_t(c)];
      }
    }
    const double change = norm > 0 ? std::sqrt(diff / norm) : 0.0;
    stats.frame_change.push_back(change);
    if (stats.convergence_frame == 0 && change < options.convergence_tolerance) {
      stats.convergence_frame = frame;
    }
  }
  last_image = rgba;
}

}  // namespace lucent::render
