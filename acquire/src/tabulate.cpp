// White Monte Carlo for the transport table (tabulate.h).
//
// The table is in optical units: sigma_t' = 1, so a medium of reduced albedo a has sigma_s' = a and
// sigma_a = 1 - a. Scattering and absorption are independent events along a path, so a medium's
// transport is its absorption-free twin (sigma_s' = a) with every path's weight multiplied by
// e^(-sigma_a L). And the absorption-free medium of sigma_s' = a is the one of sigma_s' = 1 scaled
// in length by 1 / a. So one run of the white medium (sigma_s' = 1, sigma_s = 1 / (1 - g), no
// absorption) serves every albedo: a photon event at radius rho_w after a path L_w counts for the
// medium of albedo a at radius rho_w / a with weight e^(-c L_w), c = (1 - a) / a (path lengths in
// the white medium's units, where 1 / a of them make one unit of the real medium's, times 1 - a).
// Binning happens in the real medium's radii, so nothing else rescales.
//
// Tallies per photon: its escape through the surface (exitance, with stochastic Fresnel
// reflection as in the capture simulator) and, at every scattering event, the next-event estimate
// of the radiance leaving along the normal: p_HG(d . z) e^(-sigma_s depth) T(0) / eta^2, with the
// absorption of the path to the event and of the way up. The u nodes are walked in order of
// growing c; once c L passes 40 (e^-40 = 4e-18 of the weight) the rest are skipped, so a long
// path touches only the high-albedo nodes it matters for.
//
// Oblique incidence (a slice's incidence_deg > 0): the photon starts along the refracted beam,
// sin(theta_t) = sin(theta) / eta, travelling toward +x, and every tally goes to the wedge of
// phi = atan2(|y|, x) as well as the radius bin. The white scaling is unchanged: the start
// direction does not depend on the albedo, and scaling lengths keeps phi. The radiance leaves out
// the first collision's next-event estimate there: single scattering of the beam is a line on
// the surface (y = 0), which wedges cannot hold; ObliqueModel adds it in closed form.
//
// Standard errors come from `groups` independent photon groups per slice (the spread of the group
// means), which is also what makes the table shardable: a shard computes some (slice, group)
// units, a merge puts them together, and the finishing step is the same for both.
#include "lucent/acquire/tabulate.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <numbers>
#include <string>
#include <thread>

#include "lucent/core/error.h"
#include "lucent/materials/fresnel.h"
#include "lucent/version.h"
#include "monte_carlo_random.h"

namespace lucent::acquire {
namespace {

using detail::HenyeyGreenstein;
using detail::Xoshiro256StarStar;

constexpr double kMaxOpticalWeightExponent = 40;  // e^-40: below anything a table entry can see

struct SliceConstants {
  double eta = 1, g = 0;
  double incidence = 0;         // degrees, outside
  double sin_t = 0, cos_t = 1;  // the refracted beam's direction: (sin_t, 0, -cos_t)
  double sigma_s = 1;     // white medium, units of sigma_s' = 1
  double eta_out = 1;     // 1 / eta
  double nee_factor = 1;  // T(normal, going out) / eta^2
  HenyeyGreenstein hg;
  double thickness_s = std::numeric_limits<double>::infinity();  // slab, units of 1 / sigma_s'
  bool transmitted = false;  // tally the far side
};

// Nodes of alpha' below this get a direct (absorbing) run: white Monte Carlo samples them through
// the rare short paths only (a real path of a few mean free paths is a white path of a few times
// alpha'), while the direct walk there is short and cheap.
constexpr double kDirectBelowAlbedo = 0.4;

struct AlbedoNode {
  double alpha_prime = 1;
  bool white = true;
  double c = 0;      // (1 - a) / a
  double shift = 0;  // bin index offset: -log10(a) * per_decade - log10(rho_min) * per_decade
};

std::uint64_t slice_seed(std::uint64_t seed, double eta, double g, double incidence, int group) {
  std::uint64_t h = detail::mix64(std::bit_cast<std::uint64_t>(eta)) ^
                    detail::mix64(std::bit_cast<std::uint64_t>(g) + 0x9e37);
  // Normal incidence keeps the seeds (and so the tables) of the radial builds.
  if (incidence != 0) h ^= detail::mix64(std::bit_cast<std::uint64_t>(incidence) + 0x51ed);
  return detail::stream_seed(seed ^ h, 7, static_cast<std::uint64_t>(group));
}

// One medium as a walker sees it, in units of sigma_t' = 1 (or of sigma_s' = 1 for the white run).
struct Walk {
  double sigma_t = 1;
  double albedo = 1;  // single-scattering albedo; 1 in the white run
  const SliceConstants* slice = nullptr;
  double bottom = std::numeric_limits<double>::infinity();  // slab thickness, the walk's units
};

// Traces one photon from the entry point along the refracted beam: calls escape(x, y, path,
// weight, top, scattered) when it leaves through the surface (top) or a slab's far side, and
// event(x, y, path, depth, weight, cos_up, first, direction) at each collision before it scatters
// (weight before the implicit capture; cos_up = direction[2], the direction it arrived along).
// Stops at max_path, or when Russian roulette (below a weight of 1e-4, survival 1/10) ends an
// absorbing walk.
template <typename Escape, typename Event>
void walk_photon(const Walk& m, Xoshiro256StarStar& rng, double max_path, Escape&& escape,
                 Event&& event) {
  const detail::ExponentialZiggurat& exponential = detail::exponential_ziggurat();
  const SliceConstants& s = *m.slice;
  const double inv_sigma_t = 1.0 / m.sigma_t;
  double x = 0, y = 0, z = 0, ux = s.sin_t, uy = 0, uz = -s.cos_t, w = 1, path = 0;
  bool first = true;  // no collision yet
  for (;;) {
    double step = exponential.sample(rng) * inv_sigma_t;
    for (;;) {  // boundaries crossed before the next collision: escape or internal reflection
      // Tested on where the flight ends, a well-predicted branch (the sign of uz is a coin toss
      // each collision); the division only on a crossing (z <= 0 inside: z_end >= 0 needs uz > 0
      // or uz = 0 on the surface itself).
      const double z_end = z + uz * step;
      double d;
      if (z_end >= 0 && uz > 0)
        d = -z / uz;
      else if (z_end <= -m.bottom && uz < 0)
        d = (z + m.bottom) / -uz;
      else
        break;
      if (step < d) break;
      x += ux * d;
      y += uy * d;
      z = uz > 0 ? 0 : -m.bottom;
      path += d;
      step -= d;
      const double R = materials::fresnel_reflectance(uz, s.eta_out);
      if (R < 1 && !(rng.uniform() < R)) {
        escape(x, y, path, w, uz > 0, !first);
        return;
      }
      uz = -uz;
    }
    x += ux * step;
    y += uy * step;
    z += uz * step;
    path += step;
    if (path > max_path) return;
    const std::array<double, 3> direction{ux, uy, uz};
    event(x, y, path, -z, w, uz, first, direction);
    first = false;
    if (m.albedo < 1) {
      w *= m.albedo;
      if (w < 1e-4) {
        if (!(rng.uniform() < 0.1)) return;
        w *= 10;
      }
    }
    detail::scatter_henyey_greenstein(s.hg, rng, ux, uy, uz);
  }
}

// The expected escape of a scattered photon's next flight, for the exitance of the direct runs.
// Near black the photon rarely turns up before it is absorbed (at alpha' 0.002 and g 0.92 about
// one photon in a hundred escapes, the table's entries were 12-40% noise at 10^6 photons); every
// collision instead scores the flight it would take straight out: a direction w drawn from the
// mixture of the phase function around d and the cosine lobe toward the surface (one-sample MIS,
// balance weights: f / q stays below 2 e^-tau T where the phase function dominates), weight
// p_HG(d . w) e^(-sigma_t depth / w_z) T(w_z) / q(w), landing at (dx, dy) from the collision. The
// real walk's escapes are then dropped, so each escape is counted once, in expectation; its
// internal reflections go on. In a slab (walk.bottom finite) the same flight may first reflect off
// either surface and leave after bounces between them: every bounce term is scored where it
// lands (a flight away from the surface reaches it only that way); without those, thin slabs'
// tables came out 20-30% low far out (rho 2.5-3.3 at d sigma_t' 2.6).
struct ForcedEscape {
  double weight = 0, dx = 0, dy = 0;
};
struct ForcedEscapes {
  std::array<ForcedEscape, 8> term{};
  int count = 0;
};
ForcedEscapes forced_escape(const SliceConstants& s, const Walk& m, const std::array<double, 3>& d,
                            double depth, Xoshiro256StarStar& rng) {
  double wx, wy, wz;
  if (rng.uniform() < 0.5) {
    wx = d[0], wy = d[1], wz = d[2];
    detail::scatter_henyey_greenstein(s.hg, rng, wx, wy, wz);
  } else {
    const double c2 = rng.uniform(), phi = 2 * std::numbers::pi * rng.uniform();
    wz = std::sqrt(c2);
    const double sin_t = std::sqrt(std::max(0.0, 1 - c2));
    wx = sin_t * std::cos(phi), wy = sin_t * std::sin(phi);
  }
  ForcedEscapes f;
  const bool slab = m.bottom < std::numeric_limits<double>::infinity();
  if (!(wz > 1e-9) && !(slab && wz < -1e-9)) return f;
  const double mu = std::abs(wz);
  // Path length to the surface (toward it, or by way of the other one), then per round trip.
  const double t0 = wz > 0 ? depth / mu : (2 * m.bottom - depth) / mu;
  if (m.sigma_t * t0 >= kMaxOpticalWeightExponent) return f;
  const double phase = s.hg.pdf(d[0] * wx + d[1] * wy + d[2] * wz);
  const double q = 0.5 * phase + (wz > 0 ? 0.5 * wz / std::numbers::pi : 0.0);
  const double R = materials::fresnel_reflectance(mu, s.eta_out);
  double w = phase * std::exp(-m.sigma_t * t0) * (1 - R) / q;
  if (wz < 0) w *= R;  // the reflection off the far surface on the way
  const double round_trip = slab ? 2 * m.bottom / mu : 0.0;
  const double bounce = slab ? R * R * std::exp(-m.sigma_t * round_trip) : 0.0;
  double t = t0;
  for (; f.count < int(f.term.size()); ++f.count, w *= bounce, t += round_trip) {
    if (!(w > 0) || (f.count > 0 && w < 1e-6 * f.term[0].weight)) break;
    f.term[std::size_t(f.count)] = {w, wx * t, wy * t};
  }
  return f;
}

// The next-event estimate of the radiance leaving along the normal from a collision at depth (the
// photon arrived along cos_up to the normal): the straight flight, and in a slab of thickness
// `bottom` the flights that leave after bounces (off the far surface first, or round trips), all
// landing at the same point: R(1)-weighted geometric terms, a few percent in thin slabs.
double normal_exit(const SliceConstants& s, double sigma_t, double bottom, double depth,
                   double cos_up) {
  double v = s.hg.pdf(cos_up) * std::exp(-sigma_t * depth);
  if (bottom < std::numeric_limits<double>::infinity()) {
    const double R0 = materials::fresnel_reflectance(1.0, s.eta_out);
    const double away = s.hg.pdf(-cos_up) * R0 * std::exp(-sigma_t * (2 * bottom - depth));
    v = (v + away) / (1 - R0 * R0 * std::exp(-2 * sigma_t * bottom));
  }
  return v;
}

// A group's sums as means per photon, per unit area of the real medium's annuli (or wedges of
// them, both sides of y = 0: 1 / P of the annulus); pi L for the radiance.
void normalise_group(const materials::TransportTableGrid& grid, std::size_t white_nodes,
                     std::uint64_t white_photons, std::uint64_t photons,
                     materials::TransportTableGroup& out) {
  const int J = grid.rho_bins();
  const int P = grid.phi_bins;
  std::vector<double>& exitance = out.value[0];
  std::vector<double>& radiance = out.value[1];
  const auto traced = [&](std::size_t k) {
    return double(k < white_nodes ? white_photons : photons);
  };
  for (std::size_t row = 0; row < grid.rows(); ++row) {
    const double n = traced(row / std::size_t(P));
    for (int j = 0; j < J; ++j) {
      const double r0 = grid.rho_edge(j), r1 = grid.rho_edge(j + 1);
      const double area = std::numbers::pi * (r1 * r1 - r0 * r0) / P;
      exitance[row * std::size_t(J) + std::size_t(j)] /= n * area;
      radiance[row * std::size_t(J) + std::size_t(j)] *= std::numbers::pi / (n * area);
    }
  }
  for (std::size_t k = 0; k < out.total.size(); ++k) out.total[k] /= traced(k);
}

// One (slice, group) unit: the white run for the nodes of alpha' >= kDirectBelowAlbedo, a direct
// (absorbing) run for each node below it.
void trace_group(const SliceConstants& s, const std::vector<AlbedoNode>& nodes,
                 const materials::TransportTableGrid& grid, double max_path,
                 std::uint64_t photons, std::uint64_t white_photons, Xoshiro256StarStar& rng,
                 materials::TransportTableGroup& out, std::atomic<std::uint64_t>& done) {
  const int J = grid.rho_bins();
  const int P = grid.phi_bins;
  const std::size_t K = nodes.size();
  const double per_decade = grid.rho_per_decade;
  const double log_rho_min = std::log10(grid.rho_min) * per_decade;
  std::vector<double>& exitance = out.value[0];
  std::vector<double>& radiance = out.value[1];
  exitance.assign(grid.entries(), 0.0);
  radiance.assign(grid.entries(), 0.0);
  // The wedge of a point, and the offset of its row within a u node's block of P rows.
  const auto wedge = [P](double x, double y) {
    if (P == 1) return std::size_t(0);
    const int p = int(std::atan2(std::abs(y), x) * (P / std::numbers::pi));
    return std::size_t(std::clamp(p, 0, P - 1));
  };
  out.total.assign(K, 0.0);
  std::size_t white_nodes = 0;
  while (white_nodes < K && nodes[white_nodes].white) ++white_nodes;

  // White run: each event counts for every white node k at radius rho_w / a_k with e^(-c_k L).
  const auto score = [&](std::vector<double>* tally, double x, double y, double path,
                         double weight) {
    const double rho_w = std::sqrt(x * x + y * y);
    const double lr = rho_w > 0 ? std::log10(rho_w) * per_decade : -1e300;
    const std::size_t p = wedge(x, y);
    for (std::size_t k = 0; k < white_nodes; ++k) {
      const double exponent = nodes[k].c * path;
      if (exponent > kMaxOpticalWeightExponent) break;
      const double w = weight * std::exp(-exponent);
      if (!tally) {
        out.total[k] += w;
        continue;
      }
      const double fj = lr + nodes[k].shift;
      if (fj < 0 || fj >= J) continue;
      (*tally)[(k * std::size_t(P) + p) * std::size_t(J) + std::size_t(fj)] += w;
    }
  };
  // The side tallied: the lit surface, or a slab's far side (depths and directions mirrored).
  const bool far = s.transmitted;
  const Walk white{s.sigma_s, 1.0, &s, s.thickness_s};
  if (white_nodes == 0) white_photons = 0;
  for (std::uint64_t n = 0; n < white_photons; ++n) {
    walk_photon(
        white, rng, max_path,
        [&](double x, double y, double path, double, bool top, bool scattered) {
          if (top == far || !scattered) return;  // the other side, or the unscattered beam
          score(&exitance, x, y, path, 1.0);
          score(nullptr, x, y, path, 1.0);
        },
        [&](double x, double y, double path, double depth, double, double cos_up, bool first,
            const std::array<double, 3>&) {
          // Next-event estimate of the radiance leaving along the normal.
          if (first && s.incidence != 0) return;  // the single-scattering line (above)
          const double to_surface = far ? white.bottom - depth : depth;
          if (s.sigma_s * to_surface < kMaxOpticalWeightExponent) {
            // (The bounce terms travel farther: their absorption is put at the straight
            // flight's path, a few percent of a few percent in thin absorbing slabs.)
            const double v = s.nee_factor * normal_exit(s, s.sigma_s, white.bottom, to_surface,
                                                        far ? -cos_up : cos_up);
            score(&radiance, x, y, path + to_surface, v);
          }
        });
    if ((n & 1023) == 1023) done.fetch_add(1024, std::memory_order_relaxed);
  }
  done.fetch_add(white_photons & 1023, std::memory_order_relaxed);

  // Direct runs: the absorbing medium itself, sigma_t' = 1, binned as it is.
  for (std::size_t k = white_nodes; k < K; ++k) {
    const double a = nodes[k].alpha_prime;
    const double sigma_s = a / (1 - s.g);
    // A slab of d sigma_s' = thickness_s is d sigma_t' = thickness_s / a in this walk's units.
    const Walk direct{(1 - a) + sigma_s, sigma_s / ((1 - a) + sigma_s), &s, s.thickness_s / a};
    // The entry of (x, y) in node k's rows, or -1 outside the radii.
    const auto bin = [&](double x, double y) -> long {
      const double rho = std::sqrt(x * x + y * y);
      const double fj = (rho > 0 ? std::log10(rho) * per_decade : -1e300) - log_rho_min;
      if (!(fj >= 0 && fj < J)) return -1;
      return long((k * std::size_t(P) + wedge(x, y)) * std::size_t(J) + std::size_t(fj));
    };
    for (std::uint64_t n = 0; n < photons; ++n) {
      walk_photon(
          direct, rng, max_path,
          // An escape is not scored: the collision before it scored its expected value (below).
          [](double, double, double, double, bool, bool) {},
          [&](double x, double y, double, double depth, double w, double cos_up, bool first,
              const std::array<double, 3>& arrival) {
            // The far side is the near side of the mirrored slab.
            if (far) depth = direct.bottom - depth, cos_up = -cos_up;
            const std::array<double, 3> d{arrival[0], arrival[1], far ? -arrival[2] : arrival[2]};
            const double tau = direct.sigma_t * depth;
            if (tau >= kMaxOpticalWeightExponent) return;
            // Exitance: the expected value of the next flight's escape, one sampled direction
            // up (see forced_escape), in place of the rare escapes themselves.
            const ForcedEscapes f = forced_escape(s, direct, d, depth, rng);
            for (int t = 0; t < f.count; ++t) {
              const ForcedEscape& term = f.term[std::size_t(t)];
              const double v = w * direct.albedo * term.weight;
              out.total[k] += v;
              if (const long e = bin(x + term.dx, y + term.dy); e >= 0)
                exitance[std::size_t(e)] += v;
            }
            if (first && s.incidence != 0) return;  // the single-scattering line (above)
            if (const long e = bin(x, y); e >= 0)
              radiance[std::size_t(e)] += w * direct.albedo * s.nee_factor *
                                          normal_exit(s, direct.sigma_t, direct.bottom, depth,
                                                      cos_up);
          });
    }
  }

  normalise_group(grid, white_nodes, white_photons, photons, out);
}

}  // namespace

void validate_tabulate_options(const TabulateOptions& o) {
  const auto bad = [](const std::string& what) { throw Error(what); };
  if (o.eta.empty()) bad("--eta: at least one relative index is needed");
  for (double e : o.eta)
    if (!(e >= 1.0 && e <= 2.5)) bad("--eta: each relative index must be in [1, 2.5]");
  if (o.g.empty()) bad("--g: at least one anisotropy is needed");
  if (o.incidence_deg.empty()) bad("--incidence-deg: at least one angle is needed");
  for (double a : o.incidence_deg)
    if (!(a >= 0 && a <= 85)) bad("--incidence-deg: each angle must be in [0, 85] degrees");
  for (std::size_t i = 1; i < o.incidence_deg.size(); ++i)
    if (!(o.incidence_deg[i] > o.incidence_deg[i - 1]))
      bad("--incidence-deg: the angles must be strictly increasing");
  if (o.grid.phi_bins < 1 || o.grid.phi_bins > 360) bad("--phi-bins: expected 1..360");
  if (o.grid.phi_bins == 1 && (o.incidence_deg.size() > 1 || o.incidence_deg[0] != 0))
    bad("--phi-bins: an oblique table needs azimuth wedges (e.g. 12)");
  for (double g : o.g)
    if (!(g >= 0.0 && g <= 0.99)) bad("--g: each Henyey-Greenstein g must be in [0, 0.99]");
  for (std::size_t i = 1; i < o.eta.size(); ++i)
    if (!(o.eta[i] > o.eta[i - 1])) bad("--eta: the indices must be strictly increasing");
  for (std::size_t i = 1; i < o.g.size(); ++i)
    if (!(o.g[i] > o.g[i - 1])) bad("--g: the values must be strictly increasing");
  if (o.grid.u.size() < 2 || o.grid.u.front() != 0.0) bad("grid: u nodes must start at 0");
  for (std::size_t i = 1; i < o.grid.u.size(); ++i)
    if (!(o.grid.u[i] > o.grid.u[i - 1] && o.grid.u[i] < 1)) bad("grid: u nodes must rise in [0, 1)");
  if (!(o.grid.rho_min > 0 && o.grid.rho_max > o.grid.rho_min && o.grid.rho_per_decade >= 1 &&
        o.grid.rho_per_decade <= 200))
    bad("grid: rho range or bins per decade out of range");
  if (o.groups < 2 || o.groups > 1024) bad("--groups: expected 2..1024 photon groups");
  if (o.photons < std::uint64_t(o.groups) || o.photons > 1'000'000'000'000ULL)
    bad("--photons: expected at least one photon per group and at most 1e12");
  if (o.white_photons != 0 &&
      (o.white_photons < std::uint64_t(o.groups) || o.white_photons > o.photons))
    bad("--white-photons: expected at least one photon per group and at most --photons");
  if (o.threads < 0 || o.threads > 1024) bad("--threads: expected 0 (all cores) to 1024");
  if (!(o.max_path >= 10 && o.max_path <= 1e9)) bad("--max-path: expected 10..1e9");
  if (!(o.thickness_s > 0)) bad("thickness: expected a slab thickness > 0 (d sigma_s')");
  if (o.thickness_s < std::numeric_limits<double>::infinity() &&
      (o.incidence_deg.size() != 1 || o.incidence_deg[0] != 0))
    bad("thickness: slabs are tabulated at normal incidence only");
  if (o.transmitted && !(o.thickness_s < std::numeric_limits<double>::infinity()))
    bad("side: the far side needs a finite thickness");
  if (o.shard_count < 1 || o.shard_index < 0 || o.shard_index >= o.shard_count)
    bad("--shard: expected I/N with 0 <= I < N");
}

materials::TransportTable tabulate_transport(const TabulateOptions& o,
                                             const TabulateProgress& progress) {
  validate_tabulate_options(o);
  materials::TransportTable table;
  table.grid = o.grid;
  table.seed = o.seed;
  table.groups = o.groups;
  table.max_path = o.max_path;
  table.generator = std::string("lucent ") + kVersion;
  table.slab_thickness_s = o.thickness_s;
  table.transmitted = o.transmitted;
  for (double a : o.incidence_deg)
    if (a != 0) table.single_scattering_line_excluded = true;
  const std::uint64_t per_group = (o.photons + std::uint64_t(o.groups) - 1) / std::uint64_t(o.groups);
  const std::uint64_t white_per_group =
      o.white_photons > 0 ? (o.white_photons + std::uint64_t(o.groups) - 1) / std::uint64_t(o.groups)
                          : per_group;

  std::vector<SliceConstants> slices;
  for (double incidence : o.incidence_deg) {
  for (double g : o.g) {
    for (double eta : o.eta) {
      SliceConstants s;
      s.eta = eta;
      s.g = g;
      s.incidence = incidence;
      s.sin_t = std::sin(incidence * std::numbers::pi / 180) / eta;
      s.cos_t = std::sqrt(1 - s.sin_t * s.sin_t);
      s.sigma_s = 1.0 / (1.0 - g);
      s.eta_out = 1.0 / eta;
      s.nee_factor = materials::fresnel_transmittance(1.0, s.eta_out) / (eta * eta);
      s.hg = HenyeyGreenstein(g);
      s.thickness_s = o.thickness_s;
      s.transmitted = o.transmitted;
      slices.push_back(s);
      table.slice_axes.push_back({eta, g, double(per_group * std::uint64_t(o.groups)), incidence,
                                  o.white_photons > 0 ? double(white_per_group * std::uint64_t(o.groups))
                                                      : 0.0});
    }
  }
  }
  std::vector<AlbedoNode> nodes;
  for (double u : o.grid.u) {
    const double a = 1 - u * u;
    AlbedoNode n;
    n.alpha_prime = a;
    n.white = a >= kDirectBelowAlbedo;
    n.c = (1 - a) / a;
    n.shift = (-std::log10(a) - std::log10(o.grid.rho_min)) * o.grid.rho_per_decade;
    nodes.push_back(n);
  }

  // This shard's units, in (slice, group) order.
  std::vector<std::pair<int, int>> units;
  for (int s = 0; s < int(slices.size()); ++s)
    for (int g = 0; g < o.groups; ++g)
      if ((s * o.groups + g) % o.shard_count == o.shard_index) units.emplace_back(s, g);
  std::vector<materials::TransportTableGroup> results(units.size());
  // Progress counts the white run's photons (the direct runs' are short).
  const std::uint64_t total = white_per_group * units.size();

  std::atomic<std::uint64_t> done{0};
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_mutex;
  const auto worker = [&] {
    for (;;) {
      const std::size_t i = next.fetch_add(1);
      if (i >= units.size() || failed) return;
      try {
        const auto [s, g] = units[i];
        Xoshiro256StarStar rng(
            slice_seed(o.seed, slices[s].eta, slices[s].g, slices[s].incidence, g));
        results[i].slice = s;
        results[i].group = g;
        trace_group(slices[s], nodes, o.grid, o.max_path, per_group, white_per_group, rng,
                    results[i], done);
      } catch (...) {
        std::lock_guard lock(error_mutex);
        if (!error) error = std::current_exception();
        failed = true;
      }
    }
  };
  int threads = o.threads > 0 ? o.threads : int(std::max(1u, std::thread::hardware_concurrency()));
  threads = std::min<int>(threads, int(std::max<std::size_t>(1, units.size())));
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) pool.emplace_back(worker);
  // The calling thread reports progress until the workers are done (callbacks from one thread).
  for (;;) {
    const bool finished = next.load() >= units.size() + std::size_t(threads);
    if (progress) {
      try {
        progress(std::min(done.load(), total), total);
      } catch (...) {
        std::lock_guard lock(error_mutex);
        if (!error) error = std::current_exception();
        failed = true;
      }
    }
    if (finished || failed) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  }
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  if (progress) progress(total, total);

  if (o.shard_count > 1) {
    table.partial = true;
    table.shard = std::to_string(o.shard_index) + "/" + std::to_string(o.shard_count);
    table.partial_groups = std::move(results);
    return table;
  }
  materials::finish_transport_table(table, results);
  return table;
}

}  // namespace lucent::acquire
