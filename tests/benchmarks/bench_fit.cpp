// Speed of fitting (docs/DESIGN.md §8): a 3-channel standard-dipole fit of a 150-bin radial
// profile, covariance included, one core. Run: bench_fit --benchmark_repetitions=5
//   --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <random>

#include <numbers>
#include "lucent/fit/fit.h"
#include "lucent/materials/dipole.h"
#include "lucent/materials/directional_dipole.h"
#include "lucent/materials/fresnel.h"
#include "lucent/acquire/tabulate.h"
#include "lucent/materials/profile_table.h"
#include "lucent/materials/tabulated.h"

namespace {

using namespace lucent;

// 150 annular bins out to 30 mm of marble, 1% noise, made by the standard dipole or (tabulated)
// by the transport table: each model is timed on data of its own shape (a model that cannot fit
// the data takes the restart path, and that would be timed instead).
fit::ProfileData marble_profile(bool tabulated = false) {
  const materials::Material m = materials::load_material("marble");
  fit::ProfileData d;
  d.source = "bench";
  d.eta = m.ior;
  const double ft = materials::fresnel_transmittance(1.0, m.ior);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (int i = 0; i < 150; ++i) {
    const double r0 = 0.2 * i, r1 = 0.2 * (i + 1);
    d.radial.r_inner_mm.push_back(r0);
    d.radial.r_outer_mm.push_back(r1);
    d.radial.r_mm.push_back(2.0 / 3.0 * (r1 * r1 * r1 - r0 * r0 * r0) / (r1 * r1 - r0 * r0));
    for (int c = 0; c < 3; ++c) {
      const materials::StandardDipole<double> dipole(m.medium(c));
      const double v =
          tabulated ? ft * materials::radial_profile_value(m, c, materials::DiffusionModel::kTabulated,
                                                           materials::TableQuantity::kRadiance,
                                                           d.radial.r_mm.back())
                    : ft * ft * dipole.R_d(d.radial.r_mm.back());
      d.radial.value[c].push_back(v * (1 + noise(rng)));
      d.radial.standard_error[c].push_back(0.01 * v);
    }
  }
  return d;
}

void BM_DipoleFit150Bins(benchmark::State& state) {
  const fit::ProfileData d = marble_profile();
  fit::FitOptions o;
  o.model = fit::FitModel::kDipole;
  o.systematics = false;  // the solve and its covariance alone
  o.quality = static_cast<fit::Quality>(state.range(0));
  o.analytic_derivatives = state.range(1) != 0;
  state.SetLabel(std::string(state.range(0) == 0   ? "fast"
                             : state.range(0) == 1 ? "balanced"
                                                   : "accurate") +
                 (o.analytic_derivatives ? ", analytic" : ", autodiff"));
  for (auto _ : state) {
    const fit::FitResult r = fit::fit_profiles({d}, o);
    benchmark::DoNotOptimize(r.chosen.channels[0].sigma_a);
  }
}
BENCHMARK(BM_DipoleFit150Bins)->ArgsProduct({{0, 1, 2}, {0, 1}})->Unit(benchmark::kMicrosecond);

// The tabulated model on the same 150 bins (camera data at normal incidence): the solve with its
// covariance alone (arg 0), and the whole default fit (arg 1: tabulated, the dipoles for their
// adequacy, the table bootstrap and accuracy refits, the g = 0.9 refit). The table is read once,
// outside the loop.
void BM_TabulatedFit150Bins(benchmark::State& state) {
  const fit::ProfileData d = marble_profile(true);
  fit::FitOptions o;
  o.model = state.range(0) == 0 ? fit::FitModel::kTabulated : fit::FitModel::kAuto;
  o.systematics = state.range(0) != 0;
  o.quality = fit::Quality::kBalanced;
  state.SetLabel(state.range(0) == 0 ? "tabulated solve + covariance" : "default fit, all of it");
  fit::fit_profiles({d}, o);  // reads the shipped table
  for (auto _ : state) {
    const fit::FitResult r = fit::fit_profiles({d}, o);
    benchmark::DoNotOptimize(r.chosen.channels[0].sigma_a);
  }
}
BENCHMARK(BM_TabulatedFit150Bins)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// Real benches (README "Real benches"): the tabulated solve + covariance of the same 150 bins with
// a system response (a 0.5 mm Gaussian beam: the convolution is a precomputed linear map from the
// model at ~500 radii to the bins; arg 0), and of a 5 mm slab (arg 1: slab tables of 10^5 photons
// per node built once outside the loop, about 15 s). The data are each model's own (the slab's
// from its own tables, the beam's by the same convolution done here by quadrature, with the
// once-scattered point at the entry spread by the beam).
double i0e(double x) {  // e^-x I0(x) by its series (x small) or asymptotics (x large)
  if (x < 30) {
    double sum = 0, term = 1;
    for (int k = 0; k < 200 && term > 1e-17 * sum; ++k)
      sum += term, term *= (x / 2) * (x / 2) / ((k + 1.0) * (k + 1.0));
    return std::exp(-x) * sum;
  }
  return (1 + 1 / (8 * x) + 9 / (128 * x * x)) / std::sqrt(2 * std::numbers::pi * x);
}

void BM_RealBenchFit150Bins(benchmark::State& state) {
  const bool slab = state.range(0) == 1;
  const materials::Material m = materials::load_material("marble");
  fit::FitOptions o;
  o.model = fit::FitModel::kTabulated;
  o.systematics = false;
  o.quality = fit::Quality::kBalanced;
  fit::ProfileData d = marble_profile(true);
  const double ft = materials::fresnel_transmittance(1.0, m.ior);
  if (slab) {
    acquire::TabulateOptions t;
    t.eta = {m.ior};
    t.photons = 100000;
    auto nodes = std::make_shared<materials::SlabNodes>();
    for (double thickness : {0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0}) {
      t.thickness_s = thickness;
      nodes->reflected.push_back(
          materials::TabulatedProfile::slab_node(acquire::tabulate_transport(t), 0.0));
      nodes->log_thickness_s.push_back(std::log(thickness));
    }
    o.slab = nodes;
    o.thickness_mm = 5.0;
    auto profile = std::make_shared<materials::SlabNodes>(*nodes);
    const auto semi = materials::cached_tabulated_profile(materials::default_transport_table(), 0,
                                                          m.ior);
    profile->reflected.push_back(*semi);
    profile->log_thickness_s.push_back(std::log(256.0));
    const materials::TabulatedProfile with = semi->with_slab(profile);
    for (int c = 0; c < 3; ++c) {
      const materials::TabulatedModel<double> model(with, m.medium(c), 5.0, false);
      for (std::size_t i = 0; i < d.radial.size(); ++i) {
        const double v = ft * model.radiance(d.radial.r_mm[i]);
        d.radial.value[c][i] = v;
        d.radial.standard_error[c][i] = 0.01 * v;
      }
    }
    state.SetLabel("5 mm slab: tabulated solve + covariance");
  } else {
    o.beam_sigma_mm = 0.5;
    const double s2 = 0.25;
    for (int c = 0; c < 3; ++c) {
      for (std::size_t i = 0; i < d.radial.size(); ++i) {
        const double r = d.radial.r_mm[i];
        double v = 0;
        for (double s = 0.0025; s < r + 4; s += 0.005) {
          const double f = materials::radial_profile_value(
              m, c, materials::DiffusionModel::kTabulated, materials::TableQuantity::kRadiance, s);
          v += 0.005 * s * f * std::exp(-(r - s) * (r - s) / (2 * s2)) * i0e(r * s / s2) / s2;
        }
        // The once-scattered point at the entry, spread by the beam (what the fit adds too).
        const double sa = m.sigma_a[c], ss = m.sigma_s_reduced[c];
        const double point = std::numbers::pi * ss / (sa + ss) / (4 * std::numbers::pi) *
                             materials::fresnel_transmittance(1.0, 1 / m.ior) /
                             (2 * m.ior * m.ior);
        v += point * std::exp(-r * r / (2 * s2)) / (2 * std::numbers::pi * s2);
        d.radial.value[c][i] = ft * v;
        d.radial.standard_error[c][i] = 0.01 * ft * v;
      }
    }
    state.SetLabel("0.5 mm beam: tabulated solve + covariance, model convolved");
  }
  fit::fit_profiles({d}, o);
  for (auto _ : state) {
    const fit::FitResult r = fit::fit_profiles({d}, o);
    benchmark::DoNotOptimize(r.chosen.channels[0].sigma_a);
  }
}
BENCHMARK(BM_RealBenchFit150Bins)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// A 128 x 128 oblique capture (45 degrees, 0.25 mm pixels) of marble made by the directional
// dipole, 1% noise: the directional-dipole fit's speed target (under 0.5 s).
fit::ProfileData oblique_capture() {
  const materials::Material m = materials::load_material("marble");
  fit::ProfileData d;
  d.source = "bench-oblique";
  d.eta = m.ior;
  d.incidence_polar_deg = 45;
  const double th = std::numbers::pi / 4;
  const materials::Vec3<double> w_i(-std::sin(th), 0, std::cos(th)), up(0, 0, 1);
  const double ft = materials::fresnel_transmittance(std::cos(th), m.ior) *
                    materials::fresnel_transmittance(1.0, m.ior);
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.01);
  fit::Samples2d s;
  s.pixel_mm = 0.25;
  for (int j = 0; j < 128; ++j) {
    for (int i = 0; i < 128; ++i) {
      const double x = (i + 0.5 - 64) * 0.25, y = (j + 0.5 - 64) * 0.25;
      s.x_mm.push_back(x);
      s.y_mm.push_back(y);
      for (int c = 0; c < 3; ++c) {
        const double v = ft * std::numbers::pi *
                         materials::DirectionalDipole<double>(m.medium(c))
                             .S_d(materials::Vec3<double>::Zero(), up, w_i, {x, y, 0.0}, up);
        s.value[c].push_back(v * (1 + noise(rng)));
        s.standard_error[c].push_back(0.01 * v);
      }
    }
  }
  d.samples_2d = s;
  return d;
}

void BM_DirectionalDipoleFitOblique128(benchmark::State& state) {
  const fit::ProfileData d = oblique_capture();
  fit::FitOptions o;
  o.model = fit::FitModel::kDirectionalDipole;
  o.quality = static_cast<fit::Quality>(state.range(0));
  state.SetLabel(state.range(0) == 0 ? "fast" : "balanced");
  for (auto _ : state) {
    const fit::FitResult r = fit::fit_profiles({d}, o);
    benchmark::DoNotOptimize(r.chosen.channels[0].sigma_a);
  }
}
BENCHMARK(BM_DirectionalDipoleFitOblique128)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
