// lucent tabulate (tabulate.h) and the shipped transport table against fresh runs of the capture
// simulator (photon_transport.h), which is itself held against an independent Monte Carlo code.
#include "lucent/acquire/tabulate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "lucent/acquire/photon_transport.h"
#include "lucent/core/error.h"
#include "lucent/materials/tabulated.h"
#include "lucent/materials/transport_table.h"

namespace lucent::acquire {
namespace {

using materials::TableQuantity;

TabulateOptions tiny() {
  TabulateOptions o;
  o.eta = {1.3, 1.5};
  o.grid.u = {0, 0.3, 0.7, 0.9};
  o.grid.rho_min = 0.1;
  o.grid.rho_max = 10;
  o.grid.rho_per_decade = 5;
  o.photons = 4000;
  o.groups = 4;
  o.max_path = 2000;
  return o;
}

TEST(Tabulate, DeterministicWhateverTheThreadsAndTheSharding) {
  TabulateOptions o = tiny();
  o.threads = 1;
  const materials::TransportTable one = tabulate_transport(o);
  o.threads = 2;
  const materials::TransportTable two = tabulate_transport(o);
  std::vector<materials::TransportTable> shards;
  for (int i = 0; i < 3; ++i) {
    TabulateOptions s = o;
    s.shard_index = i;
    s.shard_count = 3;
    shards.push_back(tabulate_transport(s));
    EXPECT_TRUE(shards.back().partial);
  }
  const materials::TransportTable merged = materials::merge_transport_tables(shards);
  ASSERT_EQ(one.slices.size(), 2u);
  for (std::size_t s = 0; s < one.slices.size(); ++s) {
    for (int q = 0; q < materials::kTableQuantities; ++q) {
      EXPECT_EQ(one.slices[s].value[q], two.slices[s].value[q]);
      EXPECT_EQ(one.slices[s].value[q], merged.slices[s].value[q]);
      EXPECT_EQ(one.slices[s].se_code[q], merged.slices[s].se_code[q]);
    }
    EXPECT_EQ(one.slices[s].total, merged.slices[s].total);
  }
  // Missing a shard: refused, naming the gap.
  shards.pop_back();
  EXPECT_THROW(materials::merge_transport_tables(shards), Error);
  // A different seed gives a different table.
  o.seed = 2;
  EXPECT_NE(tabulate_transport(o).slices[0].value[0], one.slices[0].value[0]);
}

// --white-photons: the white nodes' totals from a quarter of the photons agree with the full run's
// within their combined standard errors (4 SE: a handful of nodes; the direct nodes too, whose
// random stream follows the white run's), and the slice says how many it traced.
TEST(Tabulate, FewerWhitePhotonsKeepTheTotals) {
  TabulateOptions o = tiny();
  o.photons = 16000;
  const materials::TransportTable full = tabulate_transport(o);
  o.white_photons = 4000;
  const materials::TransportTable part = tabulate_transport(o);
  ASSERT_EQ(part.slices.size(), full.slices.size());
  for (std::size_t s = 0; s < full.slices.size(); ++s) {
    EXPECT_EQ(part.slices[s].white_photons, 4000u);
    for (std::size_t k = 0; k < o.grid.u.size(); ++k) {
      const double a = full.slices[s].total[k], b = part.slices[s].total[k];
      const double se = std::hypot(full.slices[s].total_se[k], part.slices[s].total_se[k]);
      EXPECT_LT(std::abs(a - b), 4 * se) << "u " << o.grid.u[k];
      EXPECT_GT(b, 0);
    }
  }
}

TEST(Tabulate, RejectsBadOptions) {
  TabulateOptions o = tiny();
  o.eta = {1.5, 1.3};
  EXPECT_THROW(tabulate_transport(o), Error);
  o = tiny();
  o.g = {0.995};  // beyond the 0.99 a white run can afford
  EXPECT_THROW(tabulate_transport(o), Error);
  o = tiny();
  o.white_photons = o.photons + 1;
  EXPECT_THROW(tabulate_transport(o), Error);
  o = tiny();
  o.shard_index = 3;
  o.shard_count = 3;
  EXPECT_THROW(tabulate_transport(o), Error);
  o = tiny();
  o.groups = 1;
  EXPECT_THROW(tabulate_transport(o), Error);
}

struct Comparison {
  int bins = 0, within = 0;  // bins with rho in [0.05, 50] and enough signal; within the bound
  int extrapolated = 0;      // bins where the table extrapolates (not judged)
  double worst_z = 0;        // largest |difference| / combined SE
  double total_error = 0;    // relative, total diffuse reflectance
  double total_z = 0;
};

// A table's exitance (the shipped one's at g = 0 unless given) against a direct simulation of
// (alpha', eta, g) at sigma_t' = 1, averaged over the simulator's annuli (Gauss-Legendre in r^2).
// Bins whose reference is noise are left out: value > 5 standard errors (more than ~25 photons),
// or above `min_signal` standard errors when given.
Comparison compare(double alpha, double eta, std::uint64_t photons,
                   const materials::TabulatedProfile* given = nullptr, double g = 0,
                   double min_signal = 5) {
  const materials::TabulatedProfile shipped(materials::default_transport_table(), 0.0);
  const materials::TabulatedProfile& profile = given ? *given : shipped;
  PhotonTransportOptions o;
  o.media[0] = materials::Medium<double>{1 - alpha, alpha / (1 - g), g, eta};
  o.channels = {true, false, false};
  o.photons = photons;
  o.image = false;
  o.seed = 7;
  o.max_radius_mm = 60;
  const PhotonTransportResult r = simulate_photon_transport(o);
  const ChannelTransportResult& ch = r.channels[0];
  const double entering = 1 - ch.specular_reflectance.value;
  const materials::TabulatedModel<double> model(profile, o.media[0]);
  constexpr double kNodes[4] = {0.0694318442, 0.3300094782, 0.6699905218, 0.9305681558};
  constexpr double kWeights[4] = {0.1739274226, 0.3260725774, 0.3260725774, 0.1739274226};
  Comparison c;
  for (std::size_t i = 0; i < r.bins.size(); ++i) {
    const double r0 = r.bins[i].r_inner_mm, r1 = r.bins[i].r_outer_mm;
    if (r0 < 0.05 || r1 > 50) continue;
    const double mc = ch.exitance[i].value / entering, se = ch.exitance[i].standard_error / entering;
    if (!(mc > min_signal * se)) continue;  // the noise, not the profile
    double tab = 0;
    for (int k = 0; k < 4; ++k)
      tab += kWeights[k] * model.R_d(std::sqrt(r0 * r0 + kNodes[k] * (r1 * r1 - r0 * r0)));
    const double tab_se = tab * profile.relative_se(TableQuantity::kExitance, r.bins[i].r_centre_mm,
                                                    alpha, eta);
    // Where the table's own entries are far-tail extrapolations (no photon of the build got
    // there: the near-black albedos far out) it claims nothing, and the fit gives those radii no
    // weight; they are counted, not judged.
    if (!std::isfinite(tab_se)) {
      ++c.extrapolated;
      continue;
    }
    const double combined = std::hypot(se, tab_se);
    const double z = std::abs(tab - mc) / combined;
    ++c.bins;
    // The bound: within 1% or 2 standard errors.
    if (std::abs(tab / mc - 1) <= 0.01 || z <= 2) ++c.within;
    c.worst_z = std::max(c.worst_z, z);
    if (z > 4 && std::getenv("LUCENT_TABLE_TEST_VERBOSE"))
      std::printf("  r %.4f..%.4f mc %.4e +- %.1e tab %.4e +- %.1e\n", r0, r1, mc, se, tab, tab_se);
  }
  const double total_mc = ch.diffuse_reflectance.value / entering;
  const double total_se = ch.diffuse_reflectance.standard_error / entering;
  const double total = model.total_diffuse_reflectance();
  c.total_error = total / total_mc - 1;
  c.total_z = std::abs(total - total_mc) /
              std::hypot(total_se, total * profile.total_relative_se(alpha, eta));
  return c;
}

// 20 (alpha', eta) points off the table's nodes, from nearly black to milk-white. A bin passes
// at "within 1% or 2 standard errors" (the table's and the run's combined): with hundreds of bins
// about 5% miss that by chance alone, so at least 90% must pass, and none may be beyond 4.5
// standard errors (a real error, not noise). Totals: within 0.5% or 2.5 standard errors.
TEST(ShippedTable, MatchesFreshSimulatorRunsOffTheGrid) {
  const std::vector<std::pair<double, double>> points{
      {0.012, 1.05}, {0.08, 1.45},  {0.2, 1.33},   {0.31, 1.17},  {0.45, 1.55},
      {0.52, 1.02},  {0.63, 1.38},  {0.71, 1.26},  {0.78, 1.49},  {0.84, 1.12},
      {0.88, 1.58},  {0.915, 1.34}, {0.94, 1.44},  {0.96, 1.08},  {0.975, 1.52},
      {0.985, 1.23}, {0.992, 1.36}, {0.996, 1.47}, {0.9985, 1.15}, {0.9994, 1.33}};
  int bins = 0, within = 0;
  for (const auto& [alpha, eta] : points) {
    // Cost per photon grows as 1 / (1 - alpha'): fewer photons for the white ones, many for the
    // near-black ones, whose far bins otherwise hold a handful of photons and a skewed mean.
    const std::uint64_t photons = alpha > 0.99  ? 12000
                                  : alpha > 0.9 ? 30000
                                  : alpha > 0.5 ? 100000
                                                : 600000;
    const Comparison c = compare(alpha, eta, photons);
    bins += c.bins;
    within += c.within;
    EXPECT_LT(c.worst_z, 4.5) << "alpha' " << alpha << " eta " << eta;
    std::printf("alpha' %.4f eta %.2f: %d bins, %d within 1%% or 2 SE, worst %.2f SE, %d "
                "extrapolated; total %+.3f%% (%.2f SE)\n",
                alpha, eta, c.bins, c.within, c.worst_z, c.extrapolated, 100 * c.total_error,
                c.total_z);
    EXPECT_TRUE(std::abs(c.total_error) < 0.005 || c.total_z < 2.5)
        << "alpha' " << alpha << " eta " << eta << ": total off by " << c.total_error << " ("
        << c.total_z << " SE)";
    EXPECT_GT(c.bins, 10) << "alpha' " << alpha;
  }
  EXPECT_GE(within, 0.9 * bins) << within << " of " << bins << " bins within 1% or 2 SE";
}

// Near black the direct runs score each collision's expected escape instead of the rare escapes
// themselves (tabulate.cpp, forced_escape). Held at nodes of a high-g slice (no interpolation in
// between) against the capture simulator, which counts real escapes: every bin with signal within
// 4 standard errors, 90% within 1% or 2, totals within 2.5 standard errors. And what it is for: at
// alpha' 0.002 and g 0.92 the escape tallies gave entries of 12-40% noise at 10^6 photons, the
// expected escapes 1-4%; here, at 10^5, the node alpha' 0.002's entries over rho 0.05..1 stay
// within 8% (5.6% measured).
TEST(Tabulate, ExpectedEscapesNearBlackMatchTheSimulator) {
  TabulateOptions o;
  o.eta = {1.3};
  o.g = {0.9};
  o.grid = materials::default_transport_grid();
  o.grid.u = {0, 0.9, 0.99, 0.999};  // alpha' 1 (white, not judged), 0.19, 0.0199, 0.002 (direct)
  o.photons = 100000;
  o.white_photons = 1600;
  const materials::TransportTable table = tabulate_transport(o);
  const materials::TabulatedProfile profile(table, 0.9);
  for (int k = 1; k < 4; ++k) {
    const double u = o.grid.u[std::size_t(k)], alpha = 1 - u * u;
    double worst_se = 0;  // the node's own entries over rho 0.05..1
    for (int j = 0; j < o.grid.rho_bins(); ++j) {
      if (o.grid.rho_edge(j) < 0.05 || o.grid.rho_edge(j + 1) > 1) continue;
      worst_se = std::max(worst_se,
                          materials::decode_relative_se(
                              table.slices[0].se_code[0][std::size_t(k * o.grid.rho_bins() + j)]));
    }
    // At 10^5 photons escape tallies would give 40-120% there (sqrt(10) x the figure above).
    if (k == 3) {
      EXPECT_LT(worst_se, 0.08) << "alpha' " << alpha;
    }
    // Reference bins of more than ~100 escapes only (10 standard errors): at g 0.9 near black
    // the escapes far out are so rare that a bin's mean is skewed low with an SE to match (at
    // rho 2, alpha' 0.002: 4.7e-9 +- 0.9e-9 from ~30 escapes against the table's 3.1e-8, where
    // single scattering alone predicts ~3e-8).
    const Comparison c =
        compare(alpha, 1.3, alpha < 0.1 ? 20'000'000 : 2'000'000, &profile, 0.9, 10);
    std::printf(
        "g 0.9 alpha' %.4f: entries within %.1f%%; %d bins, %d within 1%% or 2 SE, worst %.2f SE; "
        "total %+.3f%% "
        "(%.2f SE)\n",
        alpha, 100 * worst_se, c.bins, c.within, c.worst_z, 100 * c.total_error, c.total_z);
    EXPECT_GT(c.bins, 10) << "alpha' " << alpha;
    EXPECT_LT(c.worst_z, 4.0) << "alpha' " << alpha;
    EXPECT_GE(c.within, 0.9 * c.bins) << "alpha' " << alpha;
    EXPECT_LT(c.total_z, 2.5) << "alpha' " << alpha << ": total off by " << c.total_error;
  }
}

// A slab's tables (lucent fit --thickness-mm) against the capture simulator's slab mode, both
// sides, at albedo nodes (white and direct runs), thin and thick: the same bound as the
// semi-infinite table's (within 1% or 2 SE per bin, at least 90% of the bins, none beyond 4.5
// SE); then a thickness between the nodes through TabulatedModel's interpolation in ln(d sigma_s').
double slab_compare(const materials::TabulatedModel<double>& model,
                    const materials::TabulatedProfile& profile, double alpha, double eta,
                    double thickness, bool far, Comparison& c) {
  PhotonTransportOptions o;
  o.media[0] = materials::Medium<double>{1 - alpha, alpha, 0.0, eta};  // sigma_t' = 1: r = rho
  o.channels = {true, false, false};
  o.photons = 2'000'000;
  o.image = false;
  o.seed = 11;
  o.max_radius_mm = 60;
  o.thickness_mm = thickness;
  o.far_side = far;
  const PhotonTransportResult r = simulate_photon_transport(o);
  const ChannelTransportResult& ch = r.channels[0];
  const double entering = 1 - ch.specular_reflectance.value;
  constexpr double kNodes[4] = {0.0694318442, 0.3300094782, 0.6699905218, 0.9305681558};
  constexpr double kWeights[4] = {0.1739274226, 0.3260725774, 0.3260725774, 0.1739274226};
  double worst = 0;
  for (std::size_t i = 0; i < r.bins.size(); ++i) {
    const double r0 = r.bins[i].r_inner_mm, r1 = r.bins[i].r_outer_mm;
    if (r0 < 0.05 || r1 > 30) continue;
    const double mc = ch.exitance[i].value / entering, se = ch.exitance[i].standard_error / entering;
    if (!(mc > 10 * se)) continue;
    double tab = 0;
    for (int k = 0; k < 4; ++k)
      tab += kWeights[k] * model.R_d(std::sqrt(r0 * r0 + kNodes[k] * (r1 * r1 - r0 * r0)));
    const double tab_se = tab * profile.relative_se(TableQuantity::kExitance, r.bins[i].r_centre_mm,
                                                    alpha, eta, thickness * alpha, far);
    if (!std::isfinite(tab_se)) continue;  // an extrapolated tail claims nothing
    const double z = std::abs(tab - mc) / std::hypot(se, tab_se);
    if (z > 3 && std::getenv("LUCENT_TABLE_TEST_VERBOSE"))
      std::printf("  r %.4f..%.4f mc %.4e +- %.1e tab %.4e +- %.1e\n", r0, r1, mc, se, tab, tab_se);
    ++c.bins;
    if (std::abs(tab / mc - 1) <= 0.01 || z <= 2) ++c.within;
    c.worst_z = std::max(c.worst_z, z);
    worst = std::max(worst, std::abs(tab / mc - 1));
  }
  return worst;
}

TEST(Tabulate, SlabTablesMatchTheSimulatorOnBothSides) {
  TabulateOptions o;
  o.eta = {1.4};
  o.g = {0.0};
  o.grid = materials::default_transport_grid();
  o.grid.u = {0, 0.1, 0.3, 0.9};  // alpha' 1, 0.99, 0.91 (white run), 0.19 (direct run)
  // 500,000 photons: at 200,000 the white run's entries near rho 0.5 at d sigma_s' 2 came out 10%
  // high against 2.5% stated errors (4.7 SE; 16 groups estimate the error loosely); at 10^6 all
  // 24 cases pass with the worst bin at 3.3 SE.
  o.photons = 500000;
  for (double thickness_s : {0.5, 1.0, 2.0, 4.0}) {
    for (bool far : {false, true}) {
      o.thickness_s = thickness_s;
      o.transmitted = far;
      const materials::TransportTable table = tabulate_transport(o);
      EXPECT_TRUE(table.slab());
      EXPECT_THROW(materials::TabulatedProfile(table, 0.0), Error);  // not a semi-infinite table
      const materials::TabulatedProfile node = materials::TabulatedProfile::slab_node(table, 0.0);
      for (double u : {0.1, 0.3, 0.9}) {
        const double alpha = 1 - u * u;
        if (far && thickness_s / alpha > 8 && alpha < 0.5) continue;  // nothing comes through
        const materials::TabulatedModel<double> model(node, {1 - alpha, alpha, 0.0, 1.4});
        Comparison c;
        const double worst = slab_compare(model, node, alpha, 1.4, thickness_s / alpha, far, c);
        std::printf("slab d sigma_s' %.2f %s alpha' %.3f: %d bins, %d within 1%% or 2 SE, worst "
                    "%.2f SE, %.1f%%\n",
                    thickness_s, far ? "far side" : "lit side", alpha, c.bins, c.within,
                    c.worst_z, 100 * worst);
        EXPECT_GT(c.bins, 10);
        EXPECT_GE(c.within, 0.9 * c.bins) << thickness_s << " " << far << " " << alpha;
        EXPECT_LT(c.worst_z, 4.5) << thickness_s << " " << far << " " << alpha;
      }
    }
  }
}

TEST(Tabulate, SlabThicknessBetweenTheNodesIsInterpolated) {
  // Nodes d sigma_s' 1, 2, 4, 8 on the lit side; slabs of 1.4 and 2.8 (between the nodes) against
  // the simulator: the C1 interpolation in ln(d sigma_s') must hold the profile.
  TabulateOptions o;
  o.eta = {1.3};
  o.g = {0.0};
  o.grid = materials::default_transport_grid();
  o.grid.u = {0, 0.1, 0.3};
  o.photons = 200000;
  auto slab = std::make_shared<materials::SlabNodes>();
  for (double t : {1.0, 2.0, 4.0, 8.0}) {
    o.thickness_s = t;
    slab->reflected.push_back(materials::TabulatedProfile::slab_node(tabulate_transport(o), 0.0));
    slab->log_thickness_s.push_back(std::log(t));
  }
  o.thickness_s = std::numeric_limits<double>::infinity();
  const materials::TabulatedProfile profile =
      materials::TabulatedProfile(tabulate_transport(o), 0.0).with_slab(slab);
  for (double t : {1.4, 2.8}) {
    const double alpha = 1 - 0.1 * 0.1;
    const materials::TabulatedModel<double> model(profile, {1 - alpha, alpha, 0.0, 1.3},
                                                  t / alpha, false);
    Comparison c;
    const double worst = slab_compare(model, profile, alpha, 1.3, t / alpha, false, c);
    std::printf("interpolated slab d sigma_s' %.1f: %d bins, %d within 1%% or 2 SE, worst %.2f SE, "
                "%.1f%%\n",
                t, c.bins, c.within, c.worst_z, 100 * worst);
    EXPECT_GT(c.bins, 10);
    EXPECT_GE(c.within, 0.9 * c.bins) << t;
    EXPECT_LT(c.worst_z, 4.5) << t;
  }
}

// Beyond the table's last radius the model carries the last value by the standard dipole's
// fall-off (TabulatedModel::at). Held against a table of the same white run that reaches ten times
// further (rho 1000): at alpha' 0.9999 (u 0.01; cream's red channel is 0.99997) from rho 110 to
// 200 (further out the white run's paths, cut at 2e5, cannot reach).
TEST(Tabulate, FarFieldBeyondTheTableFollowsTransport) {
  TabulateOptions o;
  o.eta = {1.3};
  o.grid = materials::default_transport_grid();
  o.grid.u = {0, 0.01, 0.02};
  o.photons = 400000;
  materials::TransportTable near = tabulate_transport(o);
  o.grid.rho_max = 1000;
  const materials::TransportTable far = tabulate_transport(o);
  const materials::TabulatedProfile near_profile(near, 0.0), far_profile(far, 0.0);
  const double alpha = 1 - 0.01 * 0.01;
  const materials::Medium<double> m{1 - alpha, alpha, 0.0, 1.3};  // sigma_t' = 1: r = rho
  const materials::TabulatedModel<double> model(near_profile, m), truth(far_profile, m);
  double worst = 0;
  for (double rho : {110.0, 130.0, 160.0, 200.0}) {
    const double se = far_profile.relative_se(TableQuantity::kExitance, rho, alpha, 1.3);
    for (TableQuantity q : {TableQuantity::kExitance, TableQuantity::kRadiance}) {
      const double ratio = model.at(q, rho) / truth.at(q, rho);
      // The row's own extrapolation (what S_d keeps), for the record.
      const double row = alpha * std::exp(near_profile.log_value(q, rho, 0.01, 1.3));
      std::printf(
          "rho %5.0f %s: beyond / within %.4f, the row's extrapolation %.4f (table SE %.1f%%)\n",
          rho, q == TableQuantity::kExitance ? "exitance" : "radiance", ratio,
          row / truth.at(q, rho), 100 * se);
      // Measured: +5..+14% (the far table's SE 7-13%, from the same photons, so the edge value is
      // shared); the row's extrapolation +24..+81%, beyond this bound from rho 110 on.
      EXPECT_LT(std::abs(ratio - 1), std::max(0.03, 2.5 * se)) << "rho " << rho;
      worst = std::max(worst, std::abs(ratio - 1));
    }
  }
  std::printf("worst %.2f%%\n", 100 * worst);
}

}  // namespace
}  // namespace lucent::acquire
