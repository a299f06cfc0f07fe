// Private to the photon transport (photon_transport.cpp): the per-channel constants of a walk,
// the tallies, and the transport kernel (photon_kernel.cpp), one instantiation per combination of
// isotropic scattering, camera image, finite slab and split boundaries, picked at run time.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "lucent/acquire/photon_transport.h"
#include "monte_carlo_random.h"

namespace lucent::acquire::detail {

// ---------------------------------------------------------------------------------------------
// Per-channel constants of the transport.

struct Transport {
  // Medium
  double sigma_t = 0;      // mm^-1
  double inv_sigma_t = 0;  // mm (infinity when sigma_t = 0)
  double albedo = 0;
  double absorbed_fraction = 1;  // 1 - albedo
  double g = 0;
  HenyeyGreenstein hg;
  double eta_out = 1;  // relative index going out, 1 / eta
  bool finite = false;
  double thickness_mm = 0;
  bool far = false;  // the bins and the image record the bottom surface
  double beam_sigma_mm = 0;
  // Entry
  double specular = 0;
  double w0 = 1;
  double ux0 = 0, uy0 = 0, uz0 = -1;
  bool lost_to_depth = false;  // semi-infinite and sigma_t = 0: the refracted beam never comes back
  // Radial bins
  const std::vector<double>* edges = nullptr;  // inner edges plus the outer edge
  double max_radius_mm = 0;
  // Camera (next-event estimate)
  bool nee = false;
  double wt_x = 0, wt_y = 0, wt_z = 1;  // refracted camera direction inside, pointing up
  double inv_cos_t = 1;
  double nee_factor = 0;  // albedo T(cos_t) / (eta^2 cos_t A_pixel)
  double inv_pixel_mm = 0;
  double half_size = 0;
  double size_d = 0;
  int size = 0;
  double pixel_area_mm2 = 0;
};

// ---------------------------------------------------------------------------------------------
// Tallies.

struct Moments {
  double sum = 0;
  double sum_sq = 0;
  void add(double v) {
    sum += v;
    sum_sq += v * v;
  }
  void add(const Moments& other) {
    sum += other.sum;
    sum_sq += other.sum_sq;
  }
};

/// Sums over the photons of one batch (or, for the channel totals, of all merged batches).
struct Tally {
  int channel = 0;
  std::uint64_t photons = 0;
  Moments diffuse, transmitted, absorbed, image_integral;
  std::uint64_t interactions = 0;
  std::uint64_t truncated = 0;
  std::vector<Moments> bins;
  std::vector<Moments> image;
  // Pixels with a non-zero sum in this batch. Every contribution is > 0, so sum == 0 means
  // untouched.
  std::vector<std::int32_t> image_touched;

  Tally(std::size_t bin_count, std::size_t pixel_count) : bins(bin_count), image(pixel_count) {}

  /// Adds `batch` and leaves it empty for reuse.
  void merge_and_clear(Tally& batch) {
    photons += batch.photons;
    diffuse.add(batch.diffuse);
    transmitted.add(batch.transmitted);
    absorbed.add(batch.absorbed);
    image_integral.add(batch.image_integral);
    interactions += batch.interactions;
    truncated += batch.truncated;
    for (std::size_t b = 0; b < bins.size(); ++b) {
      bins[b].add(batch.bins[b]);
      batch.bins[b] = {};
    }
    for (const std::int32_t p : batch.image_touched) {
      image[static_cast<std::size_t>(p)].add(batch.image[static_cast<std::size_t>(p)]);
      batch.image[static_cast<std::size_t>(p)] = {};
    }
    batch.image_touched.clear();
    batch.photons = 0;
    batch.diffuse = batch.transmitted = batch.absorbed = batch.image_integral = {};
    batch.interactions = 0;
    batch.truncated = 0;
  }
};

/// One photon's contributions to bins and pixels, gathered so that its per-photon totals can be
/// squared. Every contribution is > 0, so a zero entry means "not touched yet by this photon".
struct PhotonScratch {
  std::vector<double> bins;
  std::vector<int> bins_touched;
  std::vector<double> image;
  std::vector<std::int32_t> image_touched;

  PhotonScratch(std::size_t bin_count, std::size_t pixel_count)
      : bins(bin_count), image(pixel_count) {
    bins_touched.reserve(64);
    image_touched.reserve(std::min<std::size_t>(pixel_count, 4096));
  }
};

/// Traces `photons` photons of channel t from `rng`, adding each one's contributions to `tally`.
using Kernel = void (*)(const Transport&, std::uint64_t, Xoshiro256StarStar&, PhotonScratch&,
                        Tally&);
/// The kernel for t's medium (isotropic below |g| 1e-6), with or without the camera image.
Kernel pick_kernel(const Transport& t, bool image, BoundaryScoring scoring);

}  // namespace lucent::acquire::detail
