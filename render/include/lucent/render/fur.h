// Seed 001 (Klotzli and Olano): a flat fur tile as stacked shells with precomputed radiance
// transfer in real SH (sh_basis.h). The CPU half: the hair generator, the anti-aliased hair
// cross-sections per shell, the offline transmittance (eq. 4) over directions on the whole sphere,
// its projection onto the 25 SH functions, and the per-texel reconstruction (the 25-term dot
// product the GPU does per fragment).
//
// Units: lengths in texels of the tile (x, y) and shells (z: one shell = `shell_spacing` texels).
//
// - Hairs (§2.1): a random base point, a base width in [width_min, width_max] (two coats with
//   their own ranges, counts and lengths) tapering linearly to 0 at the hair's length, and a
//   parabolic curl: the centre at height h is base + (h / length)^2 curl * u, u a random unit
//   direction, curl in [0, curl_max].
// - Cross-sections (§2.1): each shell's slice of a hair is a disc (radius: half the width there);
//   its coverage of each texel is the exact disc-square overlap area (`kExact`, default), or the
//   seed's chord (Harris and Stocker) and wedge approximations (`kSeed`: valid for hairs at most one
//   texel wide; measured in tests/render/fur_test.cpp: the chord within 0.8% (taken as the minor
//   segment), the wedge exact on the corner and 13-32% off once the disc moves off it). Coverage adds up and is clamped to 1 per texel; the tile wraps.
// - Transmittance (eq. 4): T(p, d) = exp(-r sum rho(p + t d) dt), marched from the voxel centre p
//   in one-texel steps (midpoint rule) with trilinear density (periodic in x, y) until the top of the volume;
//   directions into the skin (d_z <= 0) are blocked (T = 0). r: `optical_density` per texel of
//   fully covered path.
// - Transfer: t_i(p) = integral T(p, w) Y_i(w) dw by an exact product quadrature on the sphere
//   (Gauss-Legendre in cos theta x uniform azimuths, mirror-symmetric: the seed's "brighter from
//   one side" defect came from an asymmetric set); shading under a light L = sum_i c_i Y_i is
//   sum_i c_i t_i (the light reaching the voxel: the seed's lighting model, no hair BRDF).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "lucent/render/fur_coat.h"
#include "lucent/render/sh_basis.h"

namespace lucent::render::fur {

enum class CoverageRule { kExact, kSeed };
std::string to_string(CoverageRule rule);  ///< exact | seed

struct Coat {
  int hairs = 0;
  double width_min = 0, width_max = 0;  ///< base diameter, texels
  double length = 0;                    ///< in shells (1 = the full height)
};

struct FurOptions {
  int texels = 64;   ///< tile width and height
  int shells = 32;
  double shell_spacing = 1.0;  ///< texels between shells
  Coat overcoat{600, 0.6, 1.0, 1.0};
  Coat undercoat{2400, 0.2, 0.5, 0.45};
  double curl_max = 3.0;        ///< texels of lateral offset at a hair's tip
  double optical_density = 1.5;  ///< r of eq. 4 per texel of fully covered path
  CoverageRule coverage = CoverageRule::kExact;
  /// Gauss nodes in cos theta (x 2 n azimuths; the upper half used) for the transfer: 8 integrate
  /// a lobe light's relighting within 1.4% of a 32-node rule (tests/render/fur_test.cpp); the
  /// transfer's band 0 (T over the hemisphere) is +3.5% high at 8, +0.3% at 16 (fur_coat_test.cpp).
  int quadrature_nodes = 8;
  std::uint64_t seed = 1;
  /// Over a mesh (the extension: fur_coat.h, `--fur-coat`, `--technique fur` on other meshes): the
  /// tile's width and the coat's height, mm; the flat tile takes both from its mesh instead.
  double tile_mm = 8.0, height_mm = 1.5;

  void validate() const;  ///< throws lucent::Error naming the option
  std::string to_string() const;
};

struct Hair {
  Eigen::Vector2d base;   ///< texels
  double width = 0;       ///< base diameter, texels
  double length = 0;      ///< shells
  Eigen::Vector2d curl;   ///< lateral offset at the tip, texels
};

/// The hairs of both coats, deterministic for options.seed.
std::vector<Hair> generate_hairs(const FurOptions& options);

/// Area (texels^2) of the disc (centre c, radius r) inside the square [x0, x0 + 1] x [y0, y0 + 1]:
/// exact (the chord-length integral in the angle, Gauss-Legendre per smooth piece).
double disc_square_overlap(const Eigen::Vector2d& c, double r, double x0, double y0);

/// The seed's coverage of the (up to four) texels around a disc of diameter <= 1: returns the
/// fractions for texels (i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1) with i = floor(c.x - r),
/// j = floor(c.y - r), from its chord (eq. 1) and wedge (eq. 2) approximations.
std::array<double, 4> seed_coverage(const Eigen::Vector2d& c, double r);

struct FurTile {
  int texels = 0, shells = 0;
  double shell_spacing = 1;
  std::vector<float> density;   ///< [shell][y][x], coverage 0..1
  std::vector<float> transfer;  ///< [shell][y][x][25]: t_i
  float& at(int s, int y, int x) { return density[(std::size_t(s) * texels + y) * texels + x]; }
  float at(int s, int y, int x) const {
    return density[(std::size_t(s) * texels + y) * texels + x];
  }
};

/// Density only (no transfer).
FurTile rasterize_hairs(const std::vector<Hair>& hairs, const FurOptions& options);

/// T(p, d) of eq. 4 from the centre of voxel (x, y, s), d a unit direction (z up).
double transmittance(const FurTile& tile, int s, int y, int x, const Eigen::Vector3d& d,
                     double optical_density);

/// The same from the centre of every voxel of shell s at once, row-major [y][x] (`transmittance`
/// to rounding). Voxel centres sit on integer offsets, so each march step's trilinear weights are
/// shared by the whole shell: one weighted, shifted sum over a periodically padded copy per step.
std::vector<double> shell_transmittance(const FurTile& tile, int s, const Eigen::Vector3d& d,
                                        double optical_density);

/// Fills tile.transfer (multi-threaded over shells).
void compute_transfer(FurTile& tile, const FurOptions& options, int threads = 0);

/// `options` with the shell spacing (texels) of a coat height_mm tall on a tile tile_mm wide.
FurOptions over_mesh(FurOptions options);

/// The coat of options' hairs (density only, then coat_transmittance): what `--fur-coat on` adds.
FurCoat make_fur_coat(const FurOptions& options, int threads = 0);

/// The whole tile: hairs, cross-sections, transfer.
FurTile make_fur_tile(const FurOptions& options, int threads = 0);

/// The coat's transmittance to the skin (fur_coat.h): T(p, d) from every bottom-shell voxel at
/// `azimuths` mirror-symmetric azimuths, averaged, at `nodes` elevations.
FurCoat coat_transmittance(const FurTile& tile, double optical_density, int nodes = 16,
                           int azimuths = 8, int threads = 0);

/// sum_i c_i t_i at voxel (x, y, s).
double shade(const FurTile& tile, int s, int y, int x, const ShVector<double>& light);

}  // namespace lucent::render::fur
