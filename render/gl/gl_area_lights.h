// Area lights on the GPU (render/gl/shaders/area_light.glsl), shared by the real-time techniques:
// the polygons packed into the u_area_vertices uniform, the slot of each area light, and the point
// of its polygon each accumulated frame renders the light map from.
#pragma once

#include <vector>

#include "gl_api.h"
#include "lucent/render/scene.h"

namespace lucent::render::gl {

/// Area lights a GPU technique takes at once (slots of area_light.glsl).
inline constexpr int kMaxAreaLights = 4;

/// The defines every program that includes area_light.glsl needs: the slot count, and
/// LUCENT_AREA_LIGHTS when `lights` has any (the area branches cost llvmpipe a 3x slower radiance
/// pass even when no light takes them, so they are compiled only for scenes that use them).
std::vector<std::string> area_light_defines(const std::vector<Light>& lights);

bool has_area_lights(const std::vector<Light>& lights);

/// Slot of lights[l] among the area lights (0, 1, ... in order), -1 when it is not one. Throws
/// lucent::Error naming --light when there are more than kMaxAreaLights.
int area_slot(const std::vector<Light>& lights, std::size_t l);

/// Sets u_area_vertices of `program` (when it has one) from the area lights of `lights`.
void upload_area_lights(GLuint program, const std::vector<Light>& lights);

/// The point of area light `light` (its index l among all lights) for accumulated frame t >= 1:
/// the Halton (2, 3) point t of the polygon's unit square, shifted per light (Cranley-Patterson),
/// so that any number of frames covers the polygon evenly (area_light_point: uniform by area).
Vec3f area_light_frame_point(const Light& light, std::size_t l, int t);

}  // namespace lucent::render::gl
