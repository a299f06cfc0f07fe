// The point-to-polygon form factor of Jacob 1993 (Jacob 1993, §3; after Lambert's contour formula):
// the fraction of the energy leaving a differential receiver dA at x (unit normal n) that reaches
// a planar polygon, equal by reciprocity to the irradiance at x from the polygon emitting unit
// radiance, divided by pi:
//
//   F = (1 / 2 pi) sum_i  n . (R_i+1 x R_i) / |R_i+1 x R_i|  angle_i,    R_i = P_i - x,
//   angle_i = atan2(|R_i x R_i+1|, R_i . R_i+1)     (the angle edge i subtends at x, seed eq. 19),
//
// evaluated after clipping the polygon to x's tangent half-space n . (p - x) >= 0: the contour sum
// is the integral of the unclamped cosine, which counts the part of a straddling polygon below the
// horizon negatively (the seed omits the clip; a triangle cut by the horizon is ~2% off without
// it). The atan2 form keeps full precision for edges seen nearly end-on or at angles near pi,
// where acos of the normalised dot product loses half the digits.
//
// Orientation: F > 0 when x lies on the side of the polygon's winding normal (the right-hand rule
// over P_0, P_1, ...; for lucent's rect light, U x V): that is the emitting side of a one-sided
// emitter. Reversing the winding negates F; a polygon entirely behind the tangent plane gives 0.
//
// The vector form (1 / 2 pi) sum_i angle_i (R_i+1 x R_i) / |R_i+1 x R_i| (the irradiance vector
// of the unit-radiance polygon over pi; Arvo 1994) satisfies F = n . vector, and its direction is
// the polygon's irradiance-weighted mean direction from x: the w_i that Fresnel transmittance and
// the directional dipole use for an area light.
//
// Known misprints in the seed, for readers of it: eq. 10 integrates over dA_1 (it is F_{dA2 ->
// A1}), eq. 11 drops the emitter cosine, eq. 15's third term is y dx - x dy, eq. 17's denominator
// is |P + t dP|^2 and eq. 18's first arctan argument is (2w + v) / sqrt(4uw - v^2). lucent uses the
// closed contour sum above, which needs none of them.
//
// Templated on the scalar (double on the CPU; render/gl/shaders/form_factor.glsl is the float twin,
// held to this file by tests/render/glsl_twin_test.cpp).
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <span>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace lucent::render {

/// Area lights' polygons have at most this many vertices (the GLSL twin's fixed arrays; the C++
/// function itself takes any number).
inline constexpr int kMaxPolygonVertices = 8;

template <typename T>
struct PolygonFormFactor {
  using Vec3 = Eigen::Matrix<T, 3, 1>;
  T F = T(0);                  ///< signed form factor, dimensionless (see the file comment)
  Vec3 vector = Vec3::Zero();  ///< (1 / 2 pi) sum of the edge vectors; n . vector = F
  T clipped_area = T(0);       ///< mm^2 of the polygon above x's tangent plane (0 when clipped away)
};

namespace detail {

/// Accumulates the contour sum over a stream of vertices (relative to x), closing the loop at the
/// end: no storage, so the clip can run as the vertices go by and polygons have no size limit.
template <typename T>
struct ContourSum {
  using Vec3 = Eigen::Matrix<T, 3, 1>;
  Vec3 first = Vec3::Zero(), previous = Vec3::Zero();
  Vec3 vector = Vec3::Zero(), area = Vec3::Zero();
  int count = 0;

  void edge(const Vec3& a, const Vec3& b) {
    using std::atan2;
    // About the first vertex, not x: a distant receiver's long vectors would cancel in float.
    area += (a - first).cross(b - first);
    const Vec3 c = b.cross(a);
    const T length = c.norm();
    // An edge through x or seen end-on subtends no angle (and has no direction).
    if (!(length > T(0))) return;
    vector += (atan2(length, a.dot(b)) / length) * c;
  }
  void add(const Vec3& p) {
    if (count == 0) {
      first = p;
    } else {
      edge(previous, p);
    }
    previous = p;
    ++count;
  }
  void close() {
    if (count >= 3) edge(previous, first);
  }
};

}  // namespace detail

/// The form factor from the receiver (x, n: unit) to the planar polygon `vertices` (mm, any
/// number, any winding). `clip = false` skips the tangent-plane clip (the seed's formula, for
/// comparison only: wrong for polygons that straddle the horizon). Sutherland-Hodgman against
/// n . (p - x) >= 0, streamed into the contour sum.
template <typename T>
PolygonFormFactor<T> polygon_form_factor(const Eigen::Matrix<T, 3, 1>& x,
                                         const Eigen::Matrix<T, 3, 1>& n,
                                         std::span<const Eigen::Matrix<T, 3, 1>> vertices,
                                         bool clip = true) {
  using Vec3 = Eigen::Matrix<T, 3, 1>;
  PolygonFormFactor<T> result;
  const std::size_t count = vertices.size();
  if (count < 3) return result;
  detail::ContourSum<T> sum;
  for (std::size_t i = 0; i < count; ++i) {
    const Vec3 a = vertices[i] - x;
    if (!clip) {
      sum.add(a);
      continue;
    }
    const Vec3 b = vertices[(i + 1) % count] - x;
    const T da = n.dot(a), db = n.dot(b);
    if (da >= T(0)) sum.add(a);
    if ((da >= T(0)) != (db >= T(0))) sum.add(a + (da / (da - db)) * (b - a));  // da != db
  }
  if (sum.count < 3) return result;
  sum.close();
  result.vector = sum.vector / T(2 * std::numbers::pi);
  result.F = n.dot(result.vector);
  result.clipped_area = T(0.5) * sum.area.norm();
  return result;
}

/// Convenience for a std::array or vector of vertices.
template <typename T, std::size_t N>
PolygonFormFactor<T> polygon_form_factor(const Eigen::Matrix<T, 3, 1>& x,
                                         const Eigen::Matrix<T, 3, 1>& n,
                                         const std::array<Eigen::Matrix<T, 3, 1>, N>& vertices,
                                         bool clip = true) {
  return polygon_form_factor<T>(x, n, std::span<const Eigen::Matrix<T, 3, 1>>(vertices), clip);
}

}  // namespace lucent::render
