// Tests of the viewer's controls without a window (render/viewer/viewer_controls.cpp): the orbit
// camera's drag and zoom, dragging lights around the object, the sine deformer and the material
// file watcher.
#include "lucent/render/viewer_controls.h"

#include "area_light.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <thread>

namespace lucent::render {
namespace {

TEST(OrbitView, DragTurnsAndClampsZoomStaysOutsideTheObject) {
  OrbitView view;
  view.azimuth_deg = 10;
  view.elevation_deg = 0;
  view.drag(50, 0);  // grabbing the object and pulling right: the camera goes the other way
  EXPECT_NEAR(view.azimuth_deg, 10 - 50 * OrbitView::kDegreesPerPixel + 360, 1e-4);
  view.drag(0, 1000);
  EXPECT_FLOAT_EQ(view.elevation_deg, 89);
  view.drag(0, -5000);
  EXPECT_FLOAT_EQ(view.elevation_deg, -89);
  view.distance_radii = 3;
  view.zoom(1);
  EXPECT_NEAR(view.distance_radii, 2.7, 1e-5);
  view.zoom(-2);
  EXPECT_NEAR(view.distance_radii, 2.7 / 0.81, 1e-4);
  view.zoom(100);
  EXPECT_FLOAT_EQ(view.distance_radii, OrbitView::kMinDistance);
  view.zoom(-1000);
  EXPECT_FLOAT_EQ(view.distance_radii, OrbitView::kMaxDistance);
}

TEST(OrbitView, CameraIsTheOrbitCameraOfItsAngles) {
  const Mesh mesh = load_mesh("sphere", 100);
  OrbitView view{40, 25, 3.4f};
  const Camera a = view.camera(mesh, 64, 48);
  const Camera b = orbit_camera(mesh, 40, 25, 3.4f, 64, 48);
  EXPECT_LT((a.eye - b.eye).norm(), 1e-5f);
  EXPECT_EQ(a.width, 64);
  EXPECT_EQ(a.height, 48);
}

TEST(DragLight, TurnsDirectionalAndPointLightsAboutTheCentre) {
  Light sun;
  sun.direction = Vec3f(0, 0, 1);
  drag_light(sun, 90, 0);  // azimuth about +y from +z: +z turns to +x
  EXPECT_NEAR(sun.direction.x(), 1, 1e-5);
  EXPECT_NEAR(sun.direction.z(), 0, 1e-5);
  drag_light(sun, 0, 45);
  EXPECT_NEAR(sun.direction.y(), std::sqrt(0.5), 1e-5);
  EXPECT_NEAR(sun.direction.norm(), 1, 1e-5);
  drag_light(sun, 0, 90);  // clamped short of the pole, so the azimuth survives
  EXPECT_NEAR(std::asin(sun.direction.y()) * 180 / 3.14159265, 89, 1e-3);
  EXPECT_GT(sun.direction.x(), 0);

  Light lamp;
  lamp.type = LightType::kPoint;
  lamp.position = Vec3f(0, 0, 200);
  lamp.radiance = Vec3f(5, 6, 7);
  drag_light(lamp, -90, 0);
  EXPECT_NEAR(lamp.position.x(), -200, 1e-3);
  EXPECT_NEAR(lamp.position.norm(), 200, 1e-3);  // keeps its distance
  EXPECT_EQ(lamp.radiance, Vec3f(5, 6, 7));
}

TEST(SineDeformer, MovesVerticesAlongXByASineOfHeightAndRecomputesNormals) {
  const Mesh rest = load_mesh("sphere", 100);
  const SineDeformer deformer(rest, 0.05f, 1.0f, 2.0f);
  const float diagonal = (rest.bounds_max() - rest.bounds_min()).norm();
  EXPECT_NEAR(deformer.amplitude_mm(), 0.05f * diagonal, 1e-4);
  Mesh moved;
  deformer.apply(0.7, moved);
  ASSERT_EQ(moved.positions.size(), rest.positions.size());
  ASSERT_EQ(moved.normals.size(), rest.positions.size());
  EXPECT_EQ(moved.triangles, rest.triangles);
  const float y_min = rest.bounds_min().y(), height = rest.bounds_max().y() - y_min;
  float largest = 0;
  for (std::size_t i = 0; i < rest.positions.size(); ++i) {
    const Vec3f d = moved.positions[i] - rest.positions[i];
    EXPECT_EQ(d.y(), 0.0f);
    EXPECT_EQ(d.z(), 0.0f);
    const float expected = deformer.amplitude_mm() *
                           std::sin(2 * 3.14159265f * (rest.positions[i].y() - y_min) / height + 1.4f);
    EXPECT_NEAR(d.x(), expected, 1e-3f);
    largest = std::max(largest, std::abs(d.x()));
    EXPECT_NEAR(moved.normals[i].norm(), 1, 1e-5);
  }
  EXPECT_GT(largest, 0.9f * deformer.amplitude_mm());  // it does move
  // The normals follow the surface: not those of the rest sphere any more where it bends.
  float change = 0;
  for (std::size_t i = 0; i < rest.normals.size(); ++i)
    change = std::max(change, (moved.normals[i] - rest.normals[i]).norm());
  EXPECT_GT(change, 0.05f);
  // Amplitude 0: the rest mesh (normals recomputed from the faces, close to the exact ones).
  Mesh still;
  SineDeformer(rest, 0.0f).apply(3.0, still);
  EXPECT_EQ(still.positions, rest.positions);
}

TEST(FileWatcher, ReportsEachChangeOnce) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("lucent-watch-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto file = dir / "material.json";
  std::ofstream(file) << "{}";
  FileWatcher watcher(file);
  EXPECT_FALSE(watcher.changed());  // unchanged since construction
  std::ofstream(file) << "{\"name\": \"x\"}";  // another size
  EXPECT_TRUE(watcher.changed());
  EXPECT_FALSE(watcher.changed());  // once
  std::filesystem::remove(file);
  EXPECT_FALSE(watcher.changed());  // missing: wait for it
  std::ofstream(file) << "{\"name\": \"y\"}";  // back (an editor's save by rename)
  EXPECT_TRUE(watcher.changed());
  EXPECT_FALSE(FileWatcher().changed());
  std::filesystem::remove_all(dir);
}

TEST(DragLight, AreaLightTurnsRigidlyAndResizes) {
  // U x V = (0,10,0) x (20,0,0) = -z: facing the origin from +z.
  Light rect = parse_light("rect:0,0,80:0,10,0:20,0,0:1,1,1");
  ASSERT_NEAR(area_light_normal(rect).z(), -1.0f, 1e-6f);
  const double area = area_light_area(rect);
  drag_light(rect, 90, 0);  // a quarter turn about +y: from +z to +x
  EXPECT_NEAR((area_light_centroid(rect) - Vec3f(80, 0, 0)).norm(), 0.0f, 1e-3f);
  EXPECT_NEAR(area_light_normal(rect).x(), -1.0f, 1e-5f);  // still facing the origin
  EXPECT_NEAR(area_light_area(rect), area, 1e-3 * area);
  EXPECT_TRUE(resize_light(rect, 2));
  EXPECT_NEAR(area_light_area(rect), 4 * area, 1e-3 * area);
  EXPECT_NEAR((area_light_centroid(rect) - Vec3f(80, 0, 0)).norm(), 0.0f, 1e-3f);
  EXPECT_FALSE(resize_light(rect, 0));
  Light point = parse_light("point:0,0,50:1,1,1");
  EXPECT_FALSE(resize_light(point, 2));
}

}  // namespace
}  // namespace lucent::render
