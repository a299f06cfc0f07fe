// Polygonal area lights (Jacob 1993): construction, validation and sampling of the emitting polygon
// of a Light of type kArea (scene.h). Every technique evaluates the exact irradiance pi L F with
// polygon_form_factor.h; these helpers give the geometry and the stratified points on the polygon
// that the shadow rays (reference) and the per-frame light maps (radiance maps) use.
#pragma once

#include <array>
#include <vector>

#include "lucent/render/scene.h"
#include "polygon_form_factor.h"

namespace lucent::render {

/// A light emitting radiance L (W/mm^2/sr, relative) from a convex planar polygon (mm, 3 to
/// kMaxPolygonVertices vertices) toward its winding normal. Throws lucent::Error naming `what`
/// (e.g. "--light 'rect:...'") for fewer or more vertices, non-finite or degenerate (zero-area,
/// repeated-vertex) polygons, non-planar ones (off the plane by more than 1e-4 of their size) and
/// non-convex ones.
Light area_light(const std::vector<Vec3f>& polygon, const Vec3f& radiance,
                 const std::string& what = "area light");

/// The rect of `--light rect:...`: centre C, half-edge vectors U and V (mm, any non-parallel
/// pair: a parallelogram), vertices C - U - V, C + U - V, C + U + V, C - U + V, emitting toward
/// U x V.
Light rect_light(const Vec3f& centre, const Vec3f& u, const Vec3f& v, const Vec3f& radiance,
                 const std::string& what = "area light");

/// One area light per triangle of an indexed list (an emitting mesh; each triangle emits toward
/// its own winding normal).
std::vector<Light> triangle_lights(const std::vector<Vec3f>& positions,
                                   const std::vector<std::array<unsigned, 3>>& triangles,
                                   const Vec3f& radiance);

Vec3f area_light_normal(const Light& light);    ///< unit winding normal (the emitting side)
double area_light_area(const Light& light);     ///< mm^2
Vec3f area_light_centroid(const Light& light);  ///< mm, the polygon's area centroid

/// The point of the polygon at (s, t) in [0, 1)^2: uniform by area for uniform (s, t) (s picks a
/// fan triangle by its area and is rescaled within it; the triangle is sampled by the square-root
/// map), so stratified (s, t) give stratified points.
Vec3f area_light_point(const Light& light, double s, double t);

/// The far-field stand-in of an area light: a point light at its centroid with the polygon's
/// intensity along its normal, L A (the SH technique's approximation; exact as the light shrinks
/// or recedes, apart from the emitter's cosine lobe).
Light point_light_equivalent(const Light& light);

/// Translates the polygon by `offset` and scales it about its centroid by `scale` (> 0): what the
/// viewer's move and resize do.
void transform_area_light(Light& light, const Vec3f& offset, float scale);

}  // namespace lucent::render
