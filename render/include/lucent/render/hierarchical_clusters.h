// The face-cluster hierarchy of the hierarchical boundary-element technique (Mertens et al. §5.1.1,
// option 1): built bottom-up by merging neighbouring clusters, the measure only compactness (the
// seed ignores curvature when building and checks planarity, A' / A, when linking, since geometry
// and curvature change at run time). Finer clusters are embedded in coarser ones: each cluster is
// a contiguous range of `faces()` and its boundary is the oriented edge list of its faces with the
// shared (internal) edges cancelled, so that a planar cluster's form factor is its boundary's
// contour sum (hierarchical_form_factor.h).
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "lucent/render/scene.h"

namespace lucent::render::hierarchical {

struct Cluster {
  int first_face = 0, face_count = 0;  ///< range in Hierarchy::faces()
  int first_edge = 0, edge_count = 0;  ///< range in Hierarchy::boundary()
  std::array<int, 2> child{-1, -1};    ///< -1: none (a leaf has neither)
  int parent = -1;
  int depth = 0;  ///< 0 at the root
  // Geometry (mm), refreshed by Hierarchy::update_geometry.
  Eigen::Vector3d midpoint = Eigen::Vector3d::Zero();  ///< area-weighted centroid
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();   ///< area-weighted normal, unit
  double area = 0;            ///< sum of the triangles' areas, mm^2
  double projected_area = 0;  ///< |sum of a_i n_i|, the area projected on `normal`, mm^2
  double radius = 0;          ///< bounding sphere about `midpoint`, mm

  bool leaf() const { return child[0] < 0; }
  double planarity() const { return area > 0 ? projected_area / area : 0; }  ///< A' / A
};

class Hierarchy {
 public:
  /// Builds the tree over `mesh`'s triangles (vertices welded by position to find neighbours;
  /// disconnected parts are joined nearest first at the top). Throws lucent::Error on an empty mesh.
  static Hierarchy build(const Mesh& mesh);

  /// New vertex positions (same topology): every cluster's geometry, bottom-up.
  void update_geometry(const std::vector<Vec3f>& positions);

  int root() const { return root_; }
  const std::vector<Cluster>& clusters() const { return clusters_; }
  const Cluster& operator[](int id) const { return clusters_[std::size_t(id)]; }
  /// Mesh triangle indices, ordered so that every cluster's faces are contiguous.
  const std::vector<int>& faces() const { return faces_; }
  /// Oriented boundary edges as welded-vertex pairs; positions in `welded_positions()`.
  const std::vector<std::array<int, 2>>& boundary() const { return boundary_; }
  const std::vector<Eigen::Vector3d>& welded_positions() const { return welded_; }
  /// For each mesh vertex, its welded vertex.
  const std::vector<int>& weld() const { return weld_; }
  /// Leaf cluster of each mesh triangle.
  int leaf_of_face(int face) const { return leaf_of_face_[std::size_t(face)]; }
  int depth() const { return max_depth_; }

 private:
  // The stages of build(): vertices welded by position, the levels of pairwise merges (from the
  // faces' adjacency across shared edges), the depth-first order, the clusters' boundaries.
  void weld_vertices(const Mesh& mesh);
  void merge_levels(std::vector<std::vector<int>> adjacency);
  void order_depth_first();
  void build_boundaries();

  std::vector<Cluster> clusters_;
  std::vector<int> faces_, weld_, leaf_of_face_;
  std::vector<std::array<int, 3>> welded_triangles_;
  std::vector<std::array<int, 2>> boundary_;
  std::vector<Eigen::Vector3d> welded_;
  std::vector<int> post_order_;  // children before parents
  int root_ = -1, max_depth_ = 0;
};

}  // namespace lucent::render::hierarchical
