// Reading triangle meshes from PLY and OBJ bytes. lucent's own readers rather than Assimp's:
// Assimp 5.2's PLY reader reads past the end of a truncated binary file (SIGSEGV), believes a
// header's counts (std::bad_alloc at 2e9 vertices) and drops out-of-range faces without a word.
// These check every count against the bytes that are there, every index against the vertices,
// every coordinate for finiteness, and throw lucent::Error naming the file, element and item.
#pragma once

#include <string>
#include <string_view>

#include "lucent/render/scene.h"

namespace lucent::render {

/// PLY (ascii, binary_little_endian, binary_big_endian 1.0): element "vertex" with x, y, z (and
/// optionally nx, ny, nz, used when every vertex has them), element "face" with a list property
/// vertex_indices (or vertex_index); polygons are split into triangle fans; other elements and
/// properties are skipped. Positions in the file's units (load_mesh scales them).
Mesh parse_ply(std::string_view bytes, const std::string& source);

/// Wavefront OBJ: `v x y z [w]`, `vn x y z` and `f a b c ...` (a, a/t, a/t/n or a//n; negative
/// indices count back from the latest); polygons as triangle fans. Where faces give normals, a
/// vertex is a position with a normal (a cube's corner is three vertices, one per face), and a
/// corner without one gets a zero normal (load_mesh computes it). Other statements are ignored.
Mesh parse_obj(std::string_view text, const std::string& source);

/// Largest bounding-box diagonal a scene may have, mm (1 km; beyond it float positions lose the
/// sub-millimetre precision scattering needs).
inline constexpr double kMaxObjectSizeMm = 1e6;

/// `mesh` simplified to about `target_triangles`, at most that where collapses allow (a warning
/// on stderr when over 1.1 times it; meshoptimizer's quadric edge collapses, corners
/// at one position welded first; positions and triangles only: finish_mesh gives the normals). What
/// load_mesh does for "NAME@T". Throws lucent::Error naming `name` unless 4 <= T < the mesh's
/// count.
Mesh simplify_mesh(const Mesh& mesh, std::size_t target_triangles, const std::string& name);

/// Throws lucent::Error naming --object-size-mm unless 0 < size <= kMaxObjectSizeMm.
void check_object_size(double object_size_mm);

/// What load_mesh does after reading: drops degenerate triangles, refuses a mesh without any,
/// centres and scales it to `object_size_mm`, orients it outward and gives it unit normals (the
/// file's where usable; a mesh without them, crease_normals at `crease_angle_deg` below 180, else
/// area-weighted), warning about non-manifold edges.
Mesh finish_mesh(Mesh mesh, const std::string& name_or_path, double object_size_mm,
                 bool exact_normals = false, double crease_angle_deg = 180);

/// Normals with hard edges: each triangle corner gets the area-weighted normal of the triangles
/// around its vertex (corners at one position are one vertex) whose normals are within
/// `crease_angle_deg` of its own triangle's; a vertex with corners of different normals is copied,
/// one per normal (a cube's corner becomes three). Returns the vertices added. 180: smooth
/// everywhere; 0: flat.
std::size_t crease_normals(Mesh& mesh, double crease_angle_deg);

}  // namespace lucent::render
