#version 450 core
// lucent GLSL 1: Klotzli & Olano's shells: instance i of one quad per shell (back to front: bottom first
// when the eye is above the fur), or the skin (u_skin). Tile frame: x, z in [-half, half], shells at
// y = (s + 0.5) spacing.
uniform mat4 u_view_proj;
uniform float u_half_mm;
uniform float u_spacing_mm;
uniform int u_shells;
uniform bool u_reverse;  // eye below the top: top shell first
uniform bool u_skin;

out vec2 f_uv;
flat out int f_shell;

void main() {
  const vec2 corners[6] = vec2[](vec2(0, 0), vec2(1, 0), vec2(1, 1), vec2(0, 0), vec2(1, 1), vec2(0, 1));
  vec2 c = corners[gl_VertexID];
  int s = u_skin ? 0 : (u_reverse ? u_shells - 1 - gl_InstanceID : gl_InstanceID);
  float y = u_skin ? 0.0 : (float(s) + 0.5) * u_spacing_mm;
  // uv (0, 0) at (-half, -half): texel x along +x, texel y along -z (tile y = world -z).
  vec3 p = vec3(-u_half_mm + 2.0 * u_half_mm * c.x, y, u_half_mm - 2.0 * u_half_mm * c.y);
  f_uv = c;
  f_shell = s;
  gl_Position = u_view_proj * vec4(p, 1.0);
}
