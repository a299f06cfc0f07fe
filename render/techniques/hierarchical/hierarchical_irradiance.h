// The hierarchical technique's leaf irradiance (hierarchical.h): E at each triangle's midpoint,
// F_t cos included, from point and directional lights with shadow rays and from area lights through
// the projection-map cache or stratified shadow rays.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "irradiance_cache.h"
#include "lucent/materials/angular.h"
#include "lucent/render/scene.h"
#include "ray_scene.h"

namespace lucent::render::hierarchical {

/// E per mesh triangle into `face_E` (RGB, W mm^-2 per unit light); `angular`: the incidence
/// side's factor (nullptr: none). `cache` is built on first use when `use_cache` and an area light
/// is present, and kept for the next frames (reset it when the lights, eta or geometry change).
void leaf_irradiance(const Scene& scene, bool shadows, bool use_cache, double eta,
                     const materials::AngularFactor* angular, detail::RayScene* rays,
                     std::unique_ptr<detail::IrradianceCache>& cache,
                     std::vector<std::array<double, 3>>& face_E);

}  // namespace lucent::render::hierarchical
