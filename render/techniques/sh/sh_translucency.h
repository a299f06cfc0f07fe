// The CPU math core of the spherical-harmonics fast translucency technique (`--technique sh`,
// issue 12), templated on the scalar so that a GLSL twin can be held against it in float.
//
// The technique (Banterle and Chalmers 2006, "A Fast Translucency Appearance Model for Real-Time
// Applications", Banterle & Chalmers): render the lit object into an external cube map centred on
// its bounding box, project that irradiance onto the 9 real spherical harmonics of bands 0-2 per
// RGB channel (eq. 6), and shade a surface point x_out with the cosine-lobe convolution of that
// projection, looked up along the refracted view direction r, times an attenuation in the
// thickness d (eqs. 10-12):
//   L(x_out) = 1/pi F_t(eta, w_out) a(d) B(r),   B(r) = r^T M r.
//
// Sources: Ramamoorthi and Hanrahan 2001, "An efficient representation for irradiance environment
// maps" (R&H: the basis and its constants, the clamped cosine's factors A_l, c1..c5 and the 4x4
// matrix M); King 2005, GPU Gems 2 ch. 10 (the cube-map texel solid-angle weights); the OpenGL
// 4.6 core specification, "Cube Map Texture Selection" (the face / sc / tc / ma table); Jensen et
// al. 2001 (the dipole's real-source depth z_r = 1 / sigma_t', used by the attenuation's guard).
//
// Deviations from the seed as printed:
//  - Eq. 9 builds the real basis from the complex one with P_l^|m| (|m| also for m < 0); we use
//    R&H's real basis as polynomials in (x, y, z), which has no Condon-Shortley phase (every
//    constant positive). SH code that keeps the phase differs in the sign of the odd-m functions.
//  - Eq. 11 prints row 4 of M as (c1 E11, c2 E2-1, c2 E10, ...), a typo: M is symmetric, and row
//    4 is (c2 E11, c2 E1-1, c2 E10, c4 E00 - c5 E20) as in R&H.
//  - c1..c5 are the exact expressions behind the six digits of eq. 11 (irradiance_constants()),
//    and the basis constants are exact too.
//  - Eq. 12 diverges as d^-3 at d = 0 (a lit point on the light's side has zero thickness); we
//    replace d by d_eff = sqrt(d^2 + z_r^2) (attenuation()).
//  - The text says the shader evaluates "equation (4)"; it means eq. 10.
//
// Conventions: directions are unit vectors in the cube map's frame; lengths in mm, coefficients in
// mm^-1. Header-only, so that float (the shaders' twin) and double instantiate the same code.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "lucent/core/error.h"
#include "lucent/materials/medium.h"

namespace lucent::render::sh {

template <typename T>
using Vec3 = Eigen::Matrix<T, 3, 1>;
template <typename T>
using Mat4 = Eigen::Matrix<T, 4, 4>;

/// Bands l = 0, 1, 2: 9 coefficients, coefficient (l, m) at index l (l + 1) + m.
inline constexpr int kBandCount = 3;
inline constexpr int kCoefficientCount = 9;
constexpr int sh_index(int l, int m) {
  return l * (l + 1) + m;
}

template <typename T>
using Coefficients = std::array<T, kCoefficientCount>;
/// One set of coefficients per channel, R, G, B.
template <typename T>
using RgbCoefficients = std::array<Coefficients<T>, 3>;

// ---------------------------------------------------------------------------------------------
// The real SH basis of bands 0-2 (R&H).

/// Exact normalisation constants of the basis, in double (rounded once into T by the callers).
struct BasisConstants {
  double y00;  ///< 1 / (2 sqrt(pi))    = 0.282095
  double y1;   ///< sqrt(3 / (4 pi))    = 0.488603, of y, z, x
  double y2;   ///< sqrt(15 / (4 pi))   = 1.092548, of xy, yz, xz
  double y20;  ///< sqrt(5 / (16 pi))   = 0.315392, of 3 z^2 - 1
  double y22;  ///< sqrt(15 / (16 pi))  = 0.546274, of x^2 - y^2
};

inline BasisConstants basis_constants() {
  constexpr double pi = std::numbers::pi;
  return {0.5 * std::numbers::inv_sqrtpi, std::sqrt(3.0 / (4.0 * pi)), std::sqrt(15.0 / (4.0 * pi)),
          std::sqrt(5.0 / (16.0 * pi)), std::sqrt(15.0 / (16.0 * pi))};
}

/// Y_lm at the unit direction (x, y, z), in the order k = l (l + 1) + m:
///   Y00 = c; Y1-1 = c y, Y10 = c z, Y11 = c x;
///   Y2-2 = c xy, Y2-1 = c yz, Y20 = c (3 z^2 - 1), Y21 = c xz, Y22 = c (x^2 - y^2).
/// The polynomials equal the spherical harmonics on the unit sphere only (Y20 assumes |n| = 1).
template <typename T>
std::array<T, kCoefficientCount> sh_basis(T x, T y, T z) {
  const BasisConstants k = basis_constants();
  const T k1 = T(k.y1), k2 = T(k.y2);
  return {T(k.y00),
          k1 * y,
          k1 * z,
          k1 * x,
          k2 * x * y,
          k2 * y * z,
          T(k.y20) * (T(3) * z * z - T(1)),
          k2 * x * z,
          T(k.y22) * (x * x - y * y)};
}

template <typename T>
std::array<T, kCoefficientCount> sh_basis(const Vec3<T>& direction) {
  return sh_basis(direction.x(), direction.y(), direction.z());
}

// ---------------------------------------------------------------------------------------------
// Cube maps: faces, texel directions, texel solid angles.

/// Face order of GL_TEXTURE_CUBE_MAP_POSITIVE_X + face.
enum class CubeFace : int {
  kPositiveX,
  kNegativeX,
  kPositiveY,
  kNegativeY,
  kPositiveZ,
  kNegativeZ
};
inline constexpr int kCubeFaceCount = 6;

/// Face coordinate of texel index i's centre on a face of face_size texels: 2 (i + 0.5) / W - 1,
/// in (-1, 1). The same formula gives s (from i, the column) and t (from j, the row).
template <typename T>
T texel_centre_coordinate(int i, int face_size) {
  return T(2) * (T(i) + T(0.5)) / T(face_size) - T(1);
}

/// The point of the cube [-1, 1]^3 on `face` at face coordinates u = sc / |ma|, v = tc / |ma| of
/// the OpenGL table (+X: sc = -rz, tc = -ry; -X: +rz, -ry; +Y: +rx, +rz; -Y: +rx, -rz; +Z: +rx,
/// -ry; -Z: -rx, -ry), i.e. its inverse with |ma| = 1. Not normalised.
template <typename T>
Vec3<T> cube_face_point(CubeFace face, T u, T v) {
  switch (face) {
    case CubeFace::kPositiveX:
      return Vec3<T>(T(1), -v, -u);
    case CubeFace::kNegativeX:
      return Vec3<T>(T(-1), -v, u);
    case CubeFace::kPositiveY:
      return Vec3<T>(u, T(1), v);
    case CubeFace::kNegativeY:
      return Vec3<T>(u, T(-1), -v);
    case CubeFace::kPositiveZ:
      return Vec3<T>(u, -v, T(1));
    case CubeFace::kNegativeZ:
      break;
  }
  return Vec3<T>(-u, -v, T(-1));
}

/// Unit direction through the centre of texel (i, j) (column i from s = 0, row j from t = 0) of a
/// face of face_size x face_size texels.
template <typename T>
Vec3<T> cube_texel_direction(CubeFace face, int i, int j, int face_size) {
  return cube_face_point(face, texel_centre_coordinate<T>(i, face_size),
                         texel_centre_coordinate<T>(j, face_size))
      .normalized();
}

/// Where a direction falls in the cube map: the face of its major axis and u = 2 s - 1, v = 2 t
/// - 1. Ties between axes go to x, then y (the specification leaves them to the implementation).
template <typename T>
struct CubeCoordinates {
  CubeFace face;
  T u;
  T v;
};

template <typename T>
CubeCoordinates<T> cube_coordinates(const Vec3<T>& r) {
  using std::abs;
  const T ax = abs(r.x()), ay = abs(r.y()), az = abs(r.z());
  if (ax >= ay && ax >= az) {
    return r.x() >= T(0) ? CubeCoordinates<T>{CubeFace::kPositiveX, -r.z() / ax, -r.y() / ax}
                         : CubeCoordinates<T>{CubeFace::kNegativeX, r.z() / ax, -r.y() / ax};
  }
  if (ay >= az) {
    return r.y() >= T(0) ? CubeCoordinates<T>{CubeFace::kPositiveY, r.x() / ay, r.z() / ay}
                         : CubeCoordinates<T>{CubeFace::kNegativeY, r.x() / ay, -r.z() / ay};
  }
  return r.z() >= T(0) ? CubeCoordinates<T>{CubeFace::kPositiveZ, r.x() / az, -r.y() / az}
                       : CubeCoordinates<T>{CubeFace::kNegativeZ, -r.x() / az, -r.y() / az};
}

/// Differential solid angle of texel (i, j), sr: the face area (2 / W)^2 seen from the centre at
/// distance sqrt(1 + u^2 + v^2) and obliquity 1 / sqrt(1 + u^2 + v^2), at the texel centre (King
/// 2005). A midpoint rule: its sum over the sphere misses 4 pi by O(W^-2).
template <typename T>
T texel_weight(int i, int j, int face_size) {
  using std::sqrt;
  const T u = texel_centre_coordinate<T>(i, face_size);
  const T v = texel_centre_coordinate<T>(j, face_size);
  const T h = T(2) / T(face_size);
  const T q = T(1) + u * u + v * v;
  return h * h / (q * sqrt(q));
}

/// Exact solid angle of texel (i, j), sr: with Omega(a, b) = atan2(a b, sqrt(a^2 + b^2 + 1)) the
/// solid angle of the face rectangle [0, a] x [0, b] (signed), the texel [u0, u1] x [v0, v1]
/// subtends Omega(u1, v1) - Omega(u0, v1) - Omega(u1, v0) + Omega(u0, v0). The reference for
/// texel_weight().
template <typename T>
T texel_solid_angle(int i, int j, int face_size) {
  using std::atan2;
  using std::sqrt;
  const auto omega = [](T a, T b) { return atan2(a * b, sqrt(a * a + b * b + T(1))); };
  const T u0 = T(2) * T(i) / T(face_size) - T(1), u1 = T(2) * T(i + 1) / T(face_size) - T(1);
  const T v0 = T(2) * T(j) / T(face_size) - T(1), v1 = T(2) * T(j + 1) / T(face_size) - T(1);
  return omega(u1, v1) - omega(u0, v1) - omega(u1, v0) + omega(u0, v0);
}

enum class TexelWeight {
  kDifferential,  ///< texel_weight(): what a shader computes per texel (King 2005)
  kExact,         ///< texel_solid_angle(): sums to 4 pi to rounding
};

/// Calls fn(face, i, j, direction, solid_angle_sr) for every texel of a cube map with faces of
/// face_size x face_size texels. Throws lucent::Error for face_size < 1.
template <typename T, typename Fn>
void for_each_cube_texel(int face_size, TexelWeight weight, Fn&& fn) {
  if (face_size < 1) {
    throw Error("sh: cube-map face size must be at least 1 texel, got " +
                std::to_string(face_size));
  }
  for (int f = 0; f < kCubeFaceCount; ++f) {
    const auto face = static_cast<CubeFace>(f);
    for (int j = 0; j < face_size; ++j) {
      for (int i = 0; i < face_size; ++i) {
        const T d_omega = weight == TexelWeight::kExact ? texel_solid_angle<T>(i, j, face_size)
                                                        : texel_weight<T>(i, j, face_size);
        fn(face, i, j, cube_texel_direction<T>(face, i, j, face_size), d_omega);
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Projection (seed eq. 6): E_lm = sum over texels of E(w) Y_lm(w) dOmega.

/// Projects one channel, e(const Vec3<T>& direction) -> T, sampled at the texel centres of a cube
/// map with faces of face_size texels.
template <typename T, typename Radiance>
Coefficients<T> project_cube_channel(const Radiance& e, int face_size,
                                     TexelWeight weight = TexelWeight::kDifferential) {
  Coefficients<T> out{};
  for_each_cube_texel<T>(face_size, weight,
                         [&](CubeFace, int, int, const Vec3<T>& w, const T& d_omega) {
                           const T value = T(e(w)) * d_omega;
                           const auto y = sh_basis(w);
                           for (int k = 0; k < kCoefficientCount; ++k) out[k] += value * y[k];
                         });
  return out;
}

/// Projects RGB, radiance(const Vec3<T>& direction) -> anything indexable by 0, 1, 2 (e.g.
/// std::array<T, 3>): seed eq. 6 once per colour channel, one pass over the texels.
template <typename T, typename Radiance>
RgbCoefficients<T> project_cube(const Radiance& radiance, int face_size,
                                TexelWeight weight = TexelWeight::kDifferential) {
  RgbCoefficients<T> out{};
  for_each_cube_texel<T>(face_size, weight,
                         [&](CubeFace, int, int, const Vec3<T>& w, const T& d_omega) {
                           const auto rgb = radiance(w);
                           const auto y = sh_basis(w);
                           for (int c = 0; c < 3; ++c) {
                             const T value = T(rgb[c]) * d_omega;
                             for (int k = 0; k < kCoefficientCount; ++k) out[c][k] += value * y[k];
                           }
                         });
  return out;
}

// ---------------------------------------------------------------------------------------------
// Irradiance: the clamped-cosine convolution of the projection (R&H).

/// A_l of R&H, the clamped cosine's SH factors: A0 = pi, A1 = 2 pi / 3, A2 = pi / 4.
template <typename T>
std::array<T, kBandCount> cosine_lobe_factors() {
  constexpr double pi = std::numbers::pi;
  return {T(pi), T(2.0 * pi / 3.0), T(pi / 4.0)};
}

/// c1..c5 of R&H (seed eq. 11) exactly, from A_l above and the basis constants (an off-diagonal
/// entry of M counts twice in r^T M r, hence the halves):
///   c1 = A2 y22 = A2 y2 / 2 = sqrt(15 pi) / 16  = 0.4290428
///   c2 = A1 y1 / 2          = sqrt(3 pi) / 6    = 0.5116634
///   c3 = 3 A2 y20           = 3 sqrt(5 pi) / 16 = 0.7431239
///   c4 = A0 y00             = sqrt(pi) / 2      = 0.8862269
///   c5 = A2 y20             = sqrt(5 pi) / 16   = 0.2477080
/// The six digits R&H and the seed print match products of the rounded basis constants: their
/// c2 = 0.511664 and c3 = 0.743125 are 0.7e-6 and 1.1e-6 off the exact values.
struct IrradianceConstants {
  double c1, c2, c3, c4, c5;
};

inline IrradianceConstants irradiance_constants() {
  constexpr double pi = std::numbers::pi;
  return {std::sqrt(15.0 * pi) / 16.0, std::sqrt(3.0 * pi) / 6.0, 3.0 * std::sqrt(5.0 * pi) / 16.0,
          std::sqrt(pi) / 2.0, std::sqrt(5.0 * pi) / 16.0};
}

/// The symmetric 4x4 matrix M of R&H for one channel, so that B(n) = r^T M r with
/// r = (x, y, z, 1). (The seed's eq. 11 misprints row 4; see the file comment.)
template <typename T>
Mat4<T> irradiance_matrix(const Coefficients<T>& e) {
  const IrradianceConstants k = irradiance_constants();
  const T c1 = T(k.c1), c2 = T(k.c2), c3 = T(k.c3), c4 = T(k.c4), c5 = T(k.c5);
  const T& e00 = e[sh_index(0, 0)];
  const T& e1m1 = e[sh_index(1, -1)];
  const T& e10 = e[sh_index(1, 0)];
  const T& e11 = e[sh_index(1, 1)];
  const T& e2m2 = e[sh_index(2, -2)];
  const T& e2m1 = e[sh_index(2, -1)];
  const T& e20 = e[sh_index(2, 0)];
  const T& e21 = e[sh_index(2, 1)];
  const T& e22 = e[sh_index(2, 2)];
  Mat4<T> m;
  m << c1 * e22, c1 * e2m2, c1 * e21, c2 * e11,    //
      c1 * e2m2, -c1 * e22, c1 * e2m1, c2 * e1m1,  //
      c1 * e21, c1 * e2m1, c3 * e20, c2 * e10,     //
      c2 * e11, c2 * e1m1, c2 * e10, c4 * e00 - c5 * e20;
  return m;
}

template <typename T>
std::array<Mat4<T>, 3> irradiance_matrices(const RgbCoefficients<T>& e) {
  return {irradiance_matrix(e[0]), irradiance_matrix(e[1]), irradiance_matrix(e[2])};
}

/// B(n) = r^T M r, r = (x, y, z, 1), for a unit direction n (seed eq. 10): what the shader
/// computes.
template <typename T>
T irradiance(const Mat4<T>& m, const Vec3<T>& n) {
  const Eigen::Matrix<T, 4, 1> r(n.x(), n.y(), n.z(), T(1));
  return r.dot(m * r);
}

/// B(n) = sum_lm A_l E_lm Y_lm(n) (R&H): the same value summed term by term, the reference
/// for irradiance(M, n).
template <typename T>
T irradiance_from_coefficients(const Coefficients<T>& e, const Vec3<T>& n) {
  const auto a = cosine_lobe_factors<T>();
  const auto y = sh_basis(n);
  T b = T(0);
  for (int l = 0; l < kBandCount; ++l) {
    for (int m = -l; m <= l; ++m) b += a[l] * e[sh_index(l, m)] * y[sh_index(l, m)];
  }
  return b;
}

// ---------------------------------------------------------------------------------------------
// Attenuation in the thickness (seed eq. 12).

/// Seed eq. 12 as printed: (sigma_tr d + 1) e^(-sigma_tr d) / (sigma_t' d^3), mm^-2, for d in mm
/// and coefficients in mm^-1. Infinite at d = 0; the reference that attenuation() is held against.
template <typename T>
T attenuation_seed(T d_mm, T sigma_tr, T sigma_t_reduced) {
  using std::exp;
  const T s = sigma_tr * d_mm;
  return (s + T(1)) * exp(-s) / (sigma_t_reduced * d_mm * d_mm * d_mm);
}

/// Seed eq. 12 with d replaced by d_eff = sqrt(d^2 + z_r^2), z_r = 1 / sigma_t' the depth of the
/// dipole's real source (Jensen et al. 2001). It is finite at d = 0, where a lit point on the
/// light's side has zero thickness: a(0) = (sigma_tr z_r + 1) e^(-sigma_tr z_r) sigma_t'^2. Far
/// from the surface it is the seed's value to within
///   |ln(a / a_seed)| <= (z_r / d)^2 (3 + sigma_tr d) / 2
/// (from |d ln a / dd| <= 3 / d + sigma_tr and d_eff - d <= z_r^2 / (2 d)); as sigma_tr z_r <=
/// sqrt(3), the sigma_tr term stays below z_r / d. Guards: a negative d (shadow-map depth noise)
/// counts as 0; sigma_t' <= 0 (nothing scatters, z_r undefined) gives 0. In float e^(-s)
/// underflows to 0 past s = 87, where the true value is below 1.5e-36 sigma_t'^2.
template <typename T>
T attenuation(T d_mm, T sigma_tr, T sigma_t_reduced) {
  using std::exp;
  using std::sqrt;
  if (!(sigma_t_reduced > T(0))) return T(0);
  const T d = d_mm > T(0) ? d_mm : T(0);
  const T z_r = T(1) / sigma_t_reduced;
  const T d2 = d * d + z_r * z_r;
  const T d_eff = sqrt(d2);
  const T s = sigma_tr * d_eff;
  return (s + T(1)) * exp(-s) / (sigma_t_reduced * d2 * d_eff);
}

/// Eq. 12's kernel integrated over a plane at distance d (a named extension): a slab of thickness
/// d lit uniformly on its far side sends a point on its near side
///   integral over the plane of (sigma_tr r + 1) e^(-sigma_tr r) / (sigma_t' r^3) dA,
///   r^2 = d^2 + rho^2,  = 2 pi e^(-sigma_tr d) / (sigma_t' d),
/// as d/dr (-e^(-s r) / r) = (s r + 1) e^(-s r) / r^2. Eq. 12 treats the whole lit side as one
/// point at distance d and falls as d^-3; lit surface spread across the light's footprint falls as
/// d^-1 (this form), which is what a back-lit object shows near its thin parts. The same d_eff
/// guard as attenuation(); mm^-1.
template <typename T>
T attenuation_slab(T d_mm, T sigma_tr, T sigma_t_reduced) {
  using std::exp;
  using std::sqrt;
  if (!(sigma_t_reduced > T(0))) return T(0);
  const T d = d_mm > T(0) ? d_mm : T(0);
  const T z_r = T(1) / sigma_t_reduced;
  const T d_eff = sqrt(d * d + z_r * z_r);
  return T(2) * T(std::numbers::pi) * exp(-sigma_tr * d_eff) / (sigma_t_reduced * d_eff);
}

/// attenuation() with sigma_tr and sigma_t' of one channel's derived coefficients.
template <typename T>
T attenuation(T d_mm, const materials::DiffusionCoefficients<T>& c) {
  return attenuation(d_mm, c.sigma_tr, c.sigma_t_reduced);
}

// ---------------------------------------------------------------------------------------------
// Geometry of the look-up: refraction, the bounding box ("shift" and "blindness" fixes), thickness.

/// GLSL's refract(I, N, eta): the refracted direction of the unit `incident` (pointing toward the
/// surface) at a surface with unit `normal` on the incident side (incident . normal < 0), with
/// eta_ratio = n_incident / n_transmitted (1 / Medium::eta entering the object). The zero vector
/// under total internal reflection, as in GLSL.
template <typename T>
Vec3<T> refract(const Vec3<T>& incident, const Vec3<T>& normal, T eta_ratio) {
  using std::sqrt;
  const T cos_i = normal.dot(incident);
  const T k = T(1) - eta_ratio * eta_ratio * (T(1) - cos_i * cos_i);
  if (k < T(0)) return Vec3<T>::Zero();
  return eta_ratio * incident - (eta_ratio * cos_i + sqrt(k)) * normal;
}

/// Where the ray origin + t direction (t >= 0) leaves the axis-aligned box [box_min, box_max]: the
/// seed's fix of the "shift" problem looks the cube map up at this point rather than along the
/// direction from the box centre. The origin is clamped into the box first (a surface point may
/// round just outside its bounding box), and the returned point lies on the box exactly: the
/// coordinate of the exit face is set to the face's plane and the others clamped into the box. A
/// zero direction returns the clamped origin.
template <typename T>
Vec3<T> ray_box_exit(const Vec3<T>& box_min, const Vec3<T>& box_max, const Vec3<T>& origin,
                     const Vec3<T>& direction) {
  const Vec3<T> o = origin.cwiseMax(box_min).cwiseMin(box_max);
  int axis = -1;
  T t_exit = T(0);
  for (int a = 0; a < 3; ++a) {
    if (direction[a] == T(0)) continue;
    const T t = ((direction[a] > T(0) ? box_max[a] : box_min[a]) - o[a]) / direction[a];
    if (axis < 0 || t < t_exit) {
      axis = a;
      t_exit = t;
    }
  }
  if (axis < 0) return o;
  Vec3<T> p = (o + t_exit * direction).cwiseMax(box_min).cwiseMin(box_max);
  p[axis] = direction[axis] > T(0) ? box_max[axis] : box_min[axis];
  return p;
}

/// The cube-map direction of a point on the box, for an external cube map rendered with the object
/// scaled so that its bounding box becomes a cube (the seed's fix of the "blindness" problem):
/// normalize((p - centre) / half_extent), per axis. An axis of zero extent contributes 0.
template <typename T>
Vec3<T> box_lookup_direction(const Vec3<T>& box_min, const Vec3<T>& box_max, const Vec3<T>& point) {
  const Vec3<T> centre = (box_min + box_max) / T(2);
  const Vec3<T> half = (box_max - box_min) / T(2);
  Vec3<T> q;
  for (int a = 0; a < 3; ++a) q[a] = half[a] > T(0) ? (point[a] - centre[a]) / half[a] : T(0);
  return q.normalized();
}

/// Thickness of a sphere (centre, radius in mm) at surface point p as a shadow map from a light at
/// `light` (outside the sphere) measures it: |p - L| minus the distance from L to the first hit of
/// the ray from L through p, mm. 0 for points the light sees directly (up to rounding, clamped at
/// 0); the chord 2 sqrt(R^2 - b^2), b the ray's distance from the centre, for points on the far
/// side. A reference for tests of the thickness pass.
template <typename T>
T sphere_thickness(const Vec3<T>& centre, T radius, const Vec3<T>& light, const Vec3<T>& p) {
  using std::sqrt;
  const Vec3<T> to_p = p - light;
  const T dist = to_p.norm();
  const Vec3<T> u = to_p / dist;
  const Vec3<T> oc = light - centre;
  const T b = u.dot(oc);
  T disc = b * b - (oc.squaredNorm() - radius * radius);
  if (disc < T(0)) disc = T(0);  // p on the silhouette: the ray grazes, rounding may miss
  const T t_first = -b - sqrt(disc);
  const T d = dist - t_first;
  return d > T(0) ? d : T(0);
}

}  // namespace lucent::render::sh
