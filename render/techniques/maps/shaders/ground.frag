#version 450 core
// lucent GLSL 1: a Lambertian ground under the object (--ground): albedo / pi times the irradiance
// of the point and directional lights (an environment's lights among them), each shadowed by the
// object through its light map: a texel of the light map whose surface lies between the ground
// point and the light occludes it (3 x 3 texels averaged, a soft edge of a texel). Area lights do
// not light it. It fades out from 3 to 6 object radii and writes alpha 0: it is not the object
// (the mask leaves it out; auto exposure, which counts every lit pixel, sees it as it sees an
// environment's background).
in vec3 v_position;
layout(location = 0) out vec4 out_color;

layout(std140, binding = 0) uniform LightMatrices {
  mat4 u_light_view_proj[LUCENT_MAX_LIGHTS];
};
uniform int u_light_count;
uniform vec4 u_light_position[LUCENT_MAX_LIGHTS];  // w = 0: a direction toward the light
uniform vec3 u_light_radiance[LUCENT_MAX_LIGHTS];
uniform sampler2DArray u_light_positions;
uniform vec3 u_ground_albedo;
uniform vec3 u_ground_centre;
uniform float u_object_radius_mm;

const float kPi = 3.14159265358979;

float occluded_fraction(int l, vec3 x, vec3 to_light, float light_distance) {
  vec4 clip = u_light_view_proj[l] * vec4(x, 1.0);
  if (clip.w <= 0.0) return 0.0;
  vec2 uv = clip.xy / clip.w * 0.5 + 0.5;
  ivec2 size = textureSize(u_light_positions, 0).xy;
  ivec2 texel = ivec2(floor(uv * vec2(size)));
  float blocked = 0.0;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      ivec2 t = texel + ivec2(dx, dy);
      if (any(lessThan(t, ivec2(0))) || any(greaterThanEqual(t, size))) continue;
      vec4 p = texelFetch(u_light_positions, ivec3(t, l), 0);
      if (p.w < 0.5) continue;
      // The surface in this texel lies toward the light from x (and short of it).
      float along = dot(p.xyz - x, to_light);
      if (along > 1e-3 * u_object_radius_mm && along < light_distance) blocked += 1.0;
    }
  }
  return blocked / 9.0;
}

void main() {
  vec3 n = vec3(0.0, 1.0, 0.0);
  vec3 irradiance = vec3(0.0);
  for (int l = 0; l < u_light_count; ++l) {
    vec4 light = u_light_position[l];
    vec3 to_light;
    float distance_mm, falloff;
    if (light.w == 0.0) {
      to_light = normalize(light.xyz);
      distance_mm = 1e30;
      falloff = 1.0;
    } else if (light.w == 1.0) {
      vec3 d = light.xyz - v_position;
      distance_mm = length(d);
      to_light = d / max(distance_mm, 1e-6);
      falloff = 1.0 / max(distance_mm * distance_mm, 1e-12);
    } else {
      continue;  // an area light
    }
    float cosine = dot(n, to_light);
    if (cosine <= 0.0) continue;
    float lit = 1.0 - occluded_fraction(l, v_position, to_light, distance_mm);
    irradiance += u_light_radiance[l] * falloff * cosine * lit;
  }
  float r = length((v_position - u_ground_centre).xz) / u_object_radius_mm;
  float fade = 1.0 - smoothstep(3.0, 6.0, r);
  out_color = vec4(u_ground_albedo / kPi * irradiance * fade, 0.0);
}
