// The radiance maps on faceted meshes with interpolated (shading) normals, against the CPU
// reference (probes: points drawn from the profile, found on the true triangles by rays).
//
// Two things differ between a facet and its shading normal, and the maps got both wrong before:
//  - where a disc sample lands: the light map holds the surface point at each texel's centre and
//    the sample's own ray meets the surface elsewhere in the texel; the maps put it on the plane of
//    the texel's triangle (not the shading normal's tangent plane, which stands off the facet by
//    texel x tan(tilt)). A material whose mean free path is far below a texel feels this most;
//  - how much light enters: the disc's area maps onto the facet's own area, so the maps' sum was
//    of E cos_g, where the reference (and pbrt, Mitsuba) take E cos_i with the shading normal.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "gl_fixture.h"
#include "lucent/core/error.h"
#include "lucent/materials/material.h"
#include "lucent/render/image_compare.h"
#include "lucent/render/radiance_maps.h"
#include "lucent/render/reference_renderer.h"

namespace lucent::render {
namespace {

class FacetedMeshTest : public testing_gl::GlTest {};

struct Errors {
  double rmse = 0;          // relative RMSE over the object's pixels
  double worst_mean = 0;    // the channel whose mean is farthest from the reference's: |ratio - 1|
};

// The maps (K 8, N 16 or 32 of M 256) against the reference with `probes` per pixel, for a
// directional and a point light together.
Errors maps_against_reference(Scene scene, int size, int map_size, int samples, int frames,
                              int probes) {
  scene.specular = false;  // the subsurface term: the lobe is the same in both
  scene.lights = {parse_light("directional:1,0.5,0.5:1,1,1"),
                  parse_light("point:-60,60,80:5000,5000,5000")};
  scene.camera = orbit_camera(scene.mesh, 30, 20, 3.4f, size, size);  // the render command's view
  ReferenceOptions reference_options;
  reference_options.pixel_samples = probes;
  reference_options.threads = 2;
  const ReferenceImage reference =
      render_reference(scene, DiffusionModel::kDipole, reference_options);

  RenderSettings settings;
  settings.model = DiffusionModel::kDipole;
  settings.directions = 8;
  settings.samples = samples;
  settings.disc_points = 256;
  settings.radiance_map_size = map_size;
  settings.light_map_size = map_size;
  settings.frames = frames;
  RadianceMapRenderer maps;
  maps.setup(scene, settings);
  while (maps.render_frame()) {
  }
  const ImageDifference d = compare_images(maps.read_image(), reference.image, reference.mask);
  Errors e;
  e.rmse = d.relative_rmse;
  for (double r : d.mean_ratio) e.worst_mean = std::max(e.worst_mean, std::abs(r - 1));
  return e;
}

// An icosahedron split once (80 facets, 20-25 degrees between neighbours, normals = the unit
// positions) in a dense medium: mean free paths 0.05, 0.025, 0.012 mm against 1.5 mm light-map
// texels, so every sample near x_o lands within x_o's texel and its distance to x_o is that of
// the plane it is put on. Measured (40 px, W 64, N 16, 16 frames, 2048 probes): on the tangent
// plane 37% relative RMSE and channel means 0.45-0.85 of the reference; on the triangle's plane
// 6.4% and 0.95-0.99 (what is left: texels across an edge take the neighbour's plane, whose
// extension misses x_o's facet, and the terminator's texels: a finer light map shrinks both;
// seen from the front, 17% at W 64 and 9.8% at W 256). Bound: the loosest
// accuracy target (10%, ketchup's at the light settings).
TEST_F(FacetedMeshTest, DenseMediumOnACoarseIcosphereLandsOnTheFacets) {
  LUCENT_SKIP_WITHOUT_GL();
  Scene scene;
  scene.mesh = load_mesh("sphere:1", 100);
  scene.material.name = "dense";
  scene.material.ior = 1.5;
  scene.material.sigma_a = {0.05, 0.2, 1.0};
  scene.material.sigma_s_reduced = {20, 40, 80};
  const Errors e = maps_against_reference(scene, 40, 64, 16, 16, 2048);
  std::printf("sphere:1 dense: relative RMSE %.4f, worst channel mean off by %.4f\n", e.rmse,
              e.worst_mean);
  EXPECT_LT(e.rmse, 0.10);
}

// dragon:4 (11k facets, 2-4 mm) in marble: with the facet's cosine the maps were 2.3% darker
// than the reference in every channel (and every material: the factor is geometric) and 7.5%
// off in RMSE; with the shading normal's, 0.1% and 4.4% (64 px, K 8, W 256, N 32 of M 256, 32
// frames, one directional light). Bounds: the targets at the default settings (5%, 2%),
// held here at lighter ones.
TEST_F(FacetedMeshTest, CoarseDragonMatchesTheReferenceInMean) {
  LUCENT_SKIP_WITHOUT_GL();
  Scene scene;
  try {
    scene.mesh = load_mesh("dragon:4", 100);
  } catch (const Error& e) {
    GTEST_SKIP() << e.what();  // no data cache: scripts/install-deps fetches the dragon
  }
  scene.material = materials::load_material("marble");
  const Errors e = maps_against_reference(scene, 64, 256, 32, 32, 4096);
  std::printf("dragon:4 marble: relative RMSE %.4f, worst channel mean off by %.4f\n", e.rmse,
              e.worst_mean);
  EXPECT_LT(e.rmse, 0.05);
  EXPECT_LT(e.worst_mean, 0.02);
}

}  // namespace
}  // namespace lucent::render
