// The photon transport's kernel (photon_kernel.h; the scheme and its choices: the comment at the
// top of photon_transport.cpp).
#include "photon_kernel.h"

#include <cmath>
#include <numbers>

namespace lucent::acquire::detail {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRouletteThreshold = 1e-4;
constexpr double kRouletteSurvival = 0.1;
constexpr double kMaxNeeOpticalDepth = 60;

// ---------------------------------------------------------------------------------------------
// The transport kernel.

// The entry point within a Gaussian beam's footprint (Box-Muller), mm.
inline void sample_beam_footprint(double sigma_mm, Xoshiro256StarStar& rng, double& x, double& y) {
  const double radius = sigma_mm * std::sqrt(-2 * std::log(rng.uniform_open()));
  const double angle = 2 * kPi * rng.uniform();
  x = radius * std::cos(angle), y = radius * std::sin(angle);
}

// Next-event estimation toward the camera: the collision's light leaving the surface the camera
// sees, along the refracted view direction (mirrored in z for the far side: the camera below
// looks up), into the pixel it lands in.
template <bool kIsotropic>
inline void score_camera(const Transport& t, double x, double y, double z, double ux, double uy,
                         double uz, double w, PhotonScratch& scratch) {
  const double s_exit = (t.far ? z + t.thickness_mm : -z) * t.inv_cos_t;
  const double fi = (x + s_exit * t.wt_x) * t.inv_pixel_mm + t.half_size;
  const double fj = (y + s_exit * t.wt_y) * t.inv_pixel_mm + t.half_size;
  const double tau = t.sigma_t * s_exit;
  if (!(fi >= 0 && fi < t.size_d && fj >= 0 && fj < t.size_d && tau < kMaxNeeOpticalDepth)) return;
  double phase;
  if constexpr (kIsotropic) {
    phase = 1.0 / (4 * kPi);
  } else {
    phase = t.hg.pdf(ux * t.wt_x + uy * t.wt_y + (t.far ? -uz : uz) * t.wt_z);
  }
  const double v = w * t.nee_factor * phase * std::exp(-tau);
  if (v > 0) {
    const auto p = static_cast<std::size_t>(static_cast<int>(fj) * t.size + static_cast<int>(fi));
    if (scratch.image[p] == 0) scratch.image_touched.push_back(static_cast<std::int32_t>(p));
    scratch.image[p] += v;
  }
}

// One photon's totals into the tally; its scratch bins and pixels back to zero.
template <bool kImage>
inline void add_photon_totals(const Transport& t, double reflected, double transmitted,
                              double absorbed, std::uint64_t interactions, PhotonScratch& scratch,
                              Tally& tally) {
  tally.diffuse.add(reflected);
  tally.transmitted.add(transmitted);
  tally.absorbed.add(absorbed);
  tally.interactions += interactions;
  for (const int b : scratch.bins_touched) {
    tally.bins[static_cast<std::size_t>(b)].add(scratch.bins[static_cast<std::size_t>(b)]);
    scratch.bins[static_cast<std::size_t>(b)] = 0;
  }
  scratch.bins_touched.clear();
  if constexpr (kImage) {
    double integral = 0;
    for (const std::int32_t p : scratch.image_touched) {
      const auto i = static_cast<std::size_t>(p);
      const double v = scratch.image[i];
      Moments& m = tally.image[i];
      if (m.sum == 0) tally.image_touched.push_back(p);
      m.add(v);
      integral += v;
      scratch.image[i] = 0;
    }
    scratch.image_touched.clear();
    tally.image_integral.add(integral * t.pixel_area_mm2);
  }
}

template <bool kIsotropic, bool kImage, bool kFinite, bool kSplit>
void trace_photons(const Transport& t, std::uint64_t photons, Xoshiro256StarStar& rng,
                   PhotonScratch& scratch, Tally& tally) {
  const std::vector<double>& edges = *t.edges;
  const ExponentialZiggurat& exponential = exponential_ziggurat();

  for (std::uint64_t n = 0; n < photons; ++n) {
    double x = 0, y = 0, z = 0;
    if (t.beam_sigma_mm > 0) sample_beam_footprint(t.beam_sigma_mm, rng, x, y);
    double ux = t.ux0, uy = t.uy0, uz = t.uz0;
    double w = t.w0;
    double reflected = 0, transmitted = 0, absorbed = 0;
    std::uint64_t interactions = 0;

    // An escape through the top (reflected) or the bottom (transmitted); the bins record the side
    // the camera sees, scattered light only in a slab (its unscattered beam is a point at r = 0).
    auto score_exit = [&](double weight, bool top) {
      (top ? reflected : transmitted) += weight;
      if (top == t.far || (kFinite && interactions == 0)) return;
      const double r = std::sqrt(x * x + y * y);
      if (r < t.max_radius_mm) {
        const auto b = static_cast<std::size_t>(std::upper_bound(edges.begin(), edges.end(), r) -
                                                edges.begin() - 1);
        if (scratch.bins[b] == 0) scratch.bins_touched.push_back(static_cast<int>(b));
        scratch.bins[b] += weight;
      }
    };
    // Returns false when the packet dies.
    auto roulette = [&]() {
      if (w >= kRouletteThreshold) return true;
      if (rng.uniform() < kRouletteSurvival) {
        absorbed -= w * (1.0 / kRouletteSurvival - 1.0);
        w *= 1.0 / kRouletteSurvival;
        return true;
      }
      absorbed += w;
      w = 0;
      return false;
    };

    bool alive = w > 0;
    if (alive && t.lost_to_depth) {
      transmitted = w;
      alive = false;
    }
    while (alive) {
      double s = exponential.sample(rng) * t.inv_sigma_t;  // free path, mm
      // Boundaries crossed before the next collision; the rest of the free path carries over.
      // (Tested by a multiplication first: the division is needed only on a crossing.)
      for (;;) {
        // One well-predicted test on where the path ends (z <= 0 inside, so z + uz s >= 0 only
        // when uz > 0, or uz = 0 on the surface itself); the sign of uz, a coin toss each
        // collision, is looked at only on a crossing.
        const double z_end = z + uz * s;
        double d;
        if (z_end >= 0) {
          if (!(uz > 0)) break;
          d = -z / uz;
        } else if (kFinite && z_end <= -t.thickness_mm) {
          if (!(uz < 0)) break;
          d = (z + t.thickness_mm) / -uz;
        } else {
          break;
        }
        if (s < d) break;  // rounding: the product said "crossing", the distance says not
        x += ux * d;
        y += uy * d;
        const bool top = uz > 0;
        z = top ? 0.0 : -t.thickness_mm;
        s -= d;
        const double R = materials::fresnel_reflectance(std::abs(uz), t.eta_out);
        if constexpr (kSplit) {
          const double escaped = w * (1 - R);
          if (escaped > 0) {
            score_exit(escaped, top);
            w -= escaped;
          }
          uz = -uz;
          if (w == 0 || !roulette()) {  // w == 0: R = 0 (eta = 1), all of it escaped
            alive = false;
            break;
          }
        } else {
          if (R < 1 && !(rng.uniform() < R)) {
            score_exit(w, top);
            w = 0;
            alive = false;
            break;
          }
          uz = -uz;
        }
      }
      if (!alive) break;

      x += ux * s;
      y += uy * s;
      z += uz * s;
      ++interactions;

      if constexpr (kImage) {
        if (t.nee) score_camera<kIsotropic>(t, x, y, z, ux, uy, uz, w, scratch);
      }

      const double deposit = w * t.absorbed_fraction;
      absorbed += deposit;
      w -= deposit;
      if (!roulette()) break;
      if (interactions >= kMaxInteractionsPerPhoton) {
        absorbed += w;
        w = 0;
        ++tally.truncated;
        break;
      }

      // Scatter.
      if constexpr (kIsotropic) {
        sample_isotropic(rng, ux, uy, uz);
      } else {
        scatter_henyey_greenstein(t.hg, rng, ux, uy, uz);
      }
    }

    add_photon_totals<kImage>(t, reflected, transmitted, absorbed, interactions, scratch, tally);
  }
  tally.photons += photons;
}

template <bool kIsotropic, bool kImage, bool kFinite>
Kernel pick_kernel_split(bool split) {
  return split ? &trace_photons<kIsotropic, kImage, kFinite, true>
               : &trace_photons<kIsotropic, kImage, kFinite, false>;
}

template <bool kIsotropic, bool kImage>
Kernel pick_kernel_finite(bool finite, bool split) {
  return finite ? pick_kernel_split<kIsotropic, kImage, true>(split)
                : pick_kernel_split<kIsotropic, kImage, false>(split);
}

template <bool kIsotropic>
Kernel pick_kernel_image(bool image, bool finite, bool split) {
  return image ? pick_kernel_finite<kIsotropic, true>(finite, split)
               : pick_kernel_finite<kIsotropic, false>(finite, split);
}

}  // namespace

Kernel pick_kernel(const Transport& t, bool image, BoundaryScoring scoring) {
  // |g| below 1e-6 is sampled as isotropic: the mean cosine is then off by less than 1e-6, while
  // the HG inversion would lose precision to cancellation (its error grows like 1e-16 / g).
  const bool isotropic = std::abs(t.g) < 1e-6;
  const bool split = scoring == BoundaryScoring::kSplit;
  return isotropic ? pick_kernel_image<true>(image, t.finite, split)
                   : pick_kernel_image<false>(image, t.finite, split);
}

}  // namespace lucent::acquire::detail
