// The hierarchical technique's single-scattering term (Scene::single_scattering): Jensen's term
// (render/core/single_scattering.h) at every vertex toward the eye, interpolated over the triangles
// like B. The light's entry point is the first boundary crossing of an Embree ray from each
// quadrature point toward the light, and a shadow ray from there says whether the light reaches it.
// Point and directional lights (the environment's included); area lights have no term here.
#pragma once

#include <vector>

#include "lucent/render/scene.h"
#include "ray_scene.h"

namespace lucent::render::hierarchical {

/// RGB radiance per vertex (3 floats each, the vertex order of `mesh`), leaving toward `eye`.
std::vector<float> vertex_single_scattering(const detail::RayScene& rays, const Mesh& mesh,
                                            const materials::Material& material,
                                            const std::vector<Light>& lights, const Vec3f& eye,
                                            int threads);

}  // namespace lucent::render::hierarchical
