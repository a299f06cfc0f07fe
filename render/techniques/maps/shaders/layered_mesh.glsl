// lucent GLSL 1: layered rendering of the mesh (Dal Corso 2014 §5.3.2), shared by light_map.geom and
// radiance_map.geom. The mesh is drawn once, instanced: instance k is layer k; the geometry shader
// routes each triangle to gl_Layer = k with that layer's view-projection. (The seed loops over the
// layers inside the geometry shader; instancing does the same in one draw without the geometry
// shader's output-size limit on K.)
#ifndef LUCENT_LAYERED_MESH_GLSL
#define LUCENT_LAYERED_MESH_GLSL

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;

in vec3 v_position[];  // mm
in vec3 v_normal[];
flat in int v_layer[];

out vec3 g_position;
out vec3 g_normal;
// The triangle's own (flat) normal, turned to the side of its vertex normals: the plane the
// triangle's points lie in, where the interpolated normal is only a shading normal.
flat out vec3 g_face_normal;
flat out int g_layer;

invariant gl_Position;

void emit_layered_triangle(mat4 view_proj) {
  int layer = v_layer[0];
  vec3 face = cross(v_position[1] - v_position[0], v_position[2] - v_position[0]);
  if (dot(face, v_normal[0] + v_normal[1] + v_normal[2]) < 0.0) face = -face;
  float face_length = length(face);
  vec3 face_normal = face_length > 0.0 ? face / face_length : normalize(v_normal[0]);
  for (int k = 0; k < 3; ++k) {
    g_face_normal = face_normal;
    gl_Layer = layer;
    g_layer = layer;
    g_position = v_position[k];
    g_normal = v_normal[k];
    gl_Position = view_proj * vec4(v_position[k], 1.0);
    EmitVertex();
  }
  EndPrimitive();
}

#endif
