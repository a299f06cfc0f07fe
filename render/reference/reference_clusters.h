// The area sampler's irradiance records and their cluster hierarchy (reference_renderer.cpp,
// ReferenceOptions::sampling area): records of E per surface sample, a tree of clusters with their
// moments, and the gather of E S_d over it with clusters far enough away taken at sigma points.
#pragma once

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "reference_common.h"

namespace lucent::render::detail {

// ---------------------------------------------------------------------------------------------
// Irradiance records and their cluster hierarchy.

/// One surface sample lit by one light (directional dipole) or by all of them (standard dipole):
/// E already holds (A / N) * radiance * cos * V * F_t per channel.
struct Record {
  Vec3f x;  ///< mm
  Vec3f n;  ///< unit shading normal
  Vec3f w;  ///< unit direction toward the light (directional dipole only)
  std::array<float, 3> E;
};

struct ClusterNode {
  Vec3f centre;                       ///< of the bounding box of the node's samples
  float radius = 0;                   ///< bounding sphere about `centre`, mm
  std::uint32_t begin = 0, end = 0;   ///< record range
  std::uint32_t left = 0, right = 0;  ///< children; 0 for a leaf (the root is never a child)
  // Cluster summary (inner nodes only): per channel the total E, the E-weighted centroid and the
  // two sigma-point offsets sqrt(2 lambda_k) e_k; the E-weighted mean normal and light direction,
  // whose lengths measure how much the node's normals (directions) agree.
  std::array<float, 3> E{};
  std::array<Vec3f, 3> centroid;
  std::array<std::array<Vec3f, 2>, 3> axis;
  Vec3f mean_n = Vec3f::Zero();
  Vec3f mean_w = Vec3f::Zero();
};

class ClusterTree {
 public:
  static constexpr std::uint32_t kLeafSize = 4;

  explicit ClusterTree(std::vector<Record> records) : records_(std::move(records)) {
    if (records_.empty()) return;
    nodes_.reserve(2 * records_.size() / kLeafSize + 1);
    build(0, std::uint32_t(records_.size()));
  }

  const std::vector<Record>& records() const { return records_; }
  const std::vector<ClusterNode>& nodes() const { return nodes_; }
  bool empty() const { return records_.empty(); }

 private:
  std::uint32_t build(std::uint32_t begin, std::uint32_t end) {
    const std::uint32_t index = std::uint32_t(nodes_.size());
    nodes_.emplace_back();
    Eigen::AlignedBox3f box;
    for (std::uint32_t i = begin; i < end; ++i) box.extend(records_[i].x);
    ClusterNode node;
    node.centre = box.center();
    for (std::uint32_t i = begin; i < end; ++i) {
      node.radius = std::max(node.radius, (records_[i].x - node.centre).norm());
    }
    node.begin = begin;
    node.end = end;
    if (end - begin > kLeafSize) {
      summarise(node);
      int axis = 0;
      box.sizes().maxCoeff(&axis);
      const std::uint32_t mid = begin + (end - begin) / 2;
      std::nth_element(records_.begin() + begin, records_.begin() + mid, records_.begin() + end,
                       [axis](const Record& a, const Record& b) { return a.x[axis] < b.x[axis]; });
      node.left = build(begin, mid);
      node.right = build(mid, end);
    }
    nodes_[index] = node;
    return index;
  }

  void summarise(ClusterNode& node) const {
    double weight_all = 0;
    Vec3d n_sum = Vec3d::Zero(), w_sum = Vec3d::Zero();
    const Vec3d origin = node.centre.cast<double>();  // moments about the centre, for precision
    for (int c = 0; c < 3; ++c) {
      double W = 0;
      Vec3d first = Vec3d::Zero();
      Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
      for (std::uint32_t i = node.begin; i < node.end; ++i) {
        const Record& r = records_[i];
        const double e = r.E[c];
        const Vec3d y = r.x.cast<double>() - origin;
        W += e;
        first += e * y;
        second += e * y * y.transpose();
      }
      node.E[c] = float(W);
      if (!(W > 0)) {
        node.centroid[c] = node.centre;
        node.axis[c] = {Vec3f::Zero(), Vec3f::Zero()};
        continue;
      }
      const Vec3d mean = first / W;
      const Eigen::Matrix3d covariance = second / W - mean * mean.transpose();
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
      eigen.computeDirect(covariance);
      node.centroid[c] = (origin + mean).cast<float>();
      // Eigenvalues ascending: the two largest span the (locally flat) surface patch.
      for (int k = 0; k < 2; ++k) {
        const double lambda = std::max(0.0, eigen.eigenvalues()[2 - k]);
        node.axis[c][k] = (std::sqrt(2 * lambda) * eigen.eigenvectors().col(2 - k)).cast<float>();
      }
    }
    for (std::uint32_t i = node.begin; i < node.end; ++i) {
      const Record& r = records_[i];
      const double e = double(r.E[0]) + r.E[1] + r.E[2];
      weight_all += e;
      n_sum += e * r.n.cast<double>();
      w_sum += e * r.w.cast<double>();
    }
    if (weight_all > 0) {
      node.mean_n = (n_sum / weight_all).cast<float>();
      node.mean_w = (w_sum / weight_all).cast<float>();
    }
  }

  std::vector<Record> records_;
  std::vector<ClusterNode> nodes_;
};

struct GatherCounters {
  std::uint64_t exact = 0;    ///< S_d evaluations for single samples (per channel)
  std::uint64_t cluster = 0;  ///< S_d evaluations at sigma points (per channel)
};

/// sum over the tree's records of E_c S_d,c(x_i, n_i, w_i, x_o, n_o), per channel.
inline std::array<double, 3> gather(const ClusterTree& tree,
                                    const std::array<ChannelBssrdf, 3>& bssrdf,
                                    const std::array<double, 3>& r_cut, double cluster_ratio,
                                    bool needs_coherence, bool point_light, const Vec3f& x_o_f,
                                    const Vec3f& n_o_f, const Vec3f& w_o_f,
                                    GatherCounters& counters) {
  std::array<double, 3> sum{0, 0, 0};
  if (tree.empty()) return sum;
  const Vec3d x_o = x_o_f.cast<double>(), n_o = n_o_f.cast<double>(), w_o = w_o_f.cast<double>();
  const double r_cut_max = std::max({r_cut[0], r_cut[1], r_cut[2]});
  const auto& nodes = tree.nodes();
  const auto& records = tree.records();
  std::uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const ClusterNode& node = nodes[stack[--top]];
    const double d = (x_o_f - node.centre).norm();
    if (d - node.radius > r_cut_max) continue;
    if (node.left == 0) {
      for (std::uint32_t i = node.begin; i < node.end; ++i) {
        const Record& r = records[i];
        const Vec3d x_i = r.x.cast<double>();
        const double dist = (x_o - x_i).norm();
        const Vec3d n_i = r.n.cast<double>(), w_i = r.w.cast<double>();
        for (int c = 0; c < 3; ++c) {
          if (r.E[c] > 0 && dist <= r_cut[c]) {
            sum[c] += double(r.E[c]) * bssrdf[c](x_i, n_i, w_i, x_o, n_o, w_o);
            ++counters.exact;
          }
        }
      }
      continue;
    }
    bool accept = cluster_ratio > 0 && node.radius < cluster_ratio * d;
    if (accept && needs_coherence) {
      accept = node.mean_n.norm() >= 0.9f && (!point_light || node.mean_w.norm() >= 0.99f);
    }
    if (accept) {
      const Vec3d n_i = node.mean_n.cast<double>().normalized();
      const Vec3d w_i = node.mean_w.cast<double>().normalized();
      for (int c = 0; c < 3; ++c) {
        if (!(node.E[c] > 0) || d - node.radius > r_cut[c]) continue;
        const Vec3d centroid = node.centroid[c].cast<double>();
        double s = 0;
        for (int k = 0; k < 2; ++k) {
          const Vec3d a = node.axis[c][k].cast<double>();
          s += bssrdf[c](centroid + a, n_i, w_i, x_o, n_o, w_o) +
               bssrdf[c](centroid - a, n_i, w_i, x_o, n_o, w_o);
        }
        sum[c] += double(node.E[c]) * 0.25 * s;
        counters.cluster += 4;
      }
      continue;
    }
    // A fixed order (left first): the sum, rounding included, is the same on every run.
    stack[top++] = node.right;
    stack[top++] = node.left;
  }
  return sum;
}

}  // namespace lucent::render::detail
