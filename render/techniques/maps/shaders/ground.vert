#version 450 core
// lucent GLSL 1: the ground plane (Scene::ground) as one quad under the object, in mm.
uniform mat4 u_view_proj;
uniform vec3 u_ground_centre;   // mm: under the object's centre, at its lowest point
uniform float u_ground_half_mm; // half the quad's side

out vec3 v_position;

void main() {
  const vec2 corner[4] = vec2[](vec2(-1, -1), vec2(1, -1), vec2(-1, 1), vec2(1, 1));
  vec2 c = corner[gl_VertexID] * u_ground_half_mm;
  v_position = u_ground_centre + vec3(c.x, 0.0, c.y);
  gl_Position = u_view_proj * vec4(v_position, 1.0);
}
