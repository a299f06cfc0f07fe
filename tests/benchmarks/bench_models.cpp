// Evaluations per second of the standard and directional dipole, double and float, one thread; and
// the radial profile of a material (materials::radial_profile_value, what `lucent profile` and the
// Python module's lucent.profile evaluate) at 10^6 radii, three channels: the C++ side of the
// module's calling overhead (notebooks_data/bench/python_overhead.py).
// Run: build/release-or-ci/tests/benchmarks/bench_models --benchmark_repetitions=5
//        --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "lucent/materials/dipole.h"
#include "lucent/materials/directional_dipole.h"
#include "lucent/materials/material.h"
#include "lucent/materials/profile_table.h"

namespace lm = lucent::materials;

namespace {

constexpr int kConfigurations = 4096;

template <typename T>
struct Configs {
  std::vector<lm::Vec3<T>> x_o, w_i, n_o;
  std::vector<T> r;
};

template <typename T>
Configs<T> make_configs() {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  Configs<T> c;
  for (int i = 0; i < kConfigurations; ++i) {
    lm::Vec3<double> w(u(rng), u(rng), 1.0);
    c.x_o.push_back(lm::Vec3<double>(5 * u(rng), 5 * u(rng), 0).cast<T>());
    c.w_i.push_back(w.normalized().cast<T>());
    c.n_o.push_back(lm::Vec3<double>(0.1 * u(rng), 0.1 * u(rng), 1).normalized().cast<T>());
    c.r.push_back(T(5 * (u(rng) + 1)));
  }
  return c;
}

template <typename T>
lm::Medium<T> marble_red() {
  return lm::Medium<T>::from_reduced(T(0.0021), T(2.19), T(1.5));
}

template <typename T>
void BM_StandardDipole(benchmark::State& state) {
  const lm::StandardDipole<T> dipole(marble_red<T>());
  const Configs<T> c = make_configs<T>();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(dipole.R_d(c.r[i]));
    i = (i + 1) % kConfigurations;
  }
  state.SetItemsProcessed(state.iterations());
}

template <typename T>
void BM_DirectionalDipole(benchmark::State& state) {
  const lm::DirectionalDipole<T> dd(marble_red<T>());
  const Configs<T> c = make_configs<T>();
  const lm::Vec3<T> up(T(0), T(0), T(1));
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(dd.S_d(lm::Vec3<T>::Zero(), up, c.w_i[i], c.x_o[i], c.n_o[i]));
    i = (i + 1) % kConfigurations;
  }
  state.SetItemsProcessed(state.iterations());
}

}  // namespace

BENCHMARK(BM_StandardDipole<double>);
BENCHMARK(BM_StandardDipole<float>);
BENCHMARK(BM_DirectionalDipole<double>);
BENCHMARK(BM_DirectionalDipole<float>);
// 10^6 radii log-spaced over 0.01-50 mm, marble, R, G and B: one call per radius and channel.
void BM_RadialProfile(benchmark::State& state) {
  const auto model = static_cast<lm::DiffusionModel>(state.range(0));
  const lm::Material marble = lm::load_material("marble");
  constexpr int kRadii = 1'000'000;
  std::vector<double> r(kRadii), out(3 * std::size_t(kRadii));
  for (int i = 0; i < kRadii; ++i) r[i] = 0.01 * std::pow(5000.0, double(i) / (kRadii - 1));
  for (auto _ : state) {
    for (int i = 0; i < kRadii; ++i)
      for (int c = 0; c < 3; ++c)
        out[3 * std::size_t(i) + c] = lm::radial_profile_value(
            marble, c, model, lm::TableQuantity::kExitance, r[std::size_t(i)]);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * kRadii);
  state.SetLabel(lm::to_string(model));
}
BENCHMARK(BM_RadialProfile)
    ->Arg(int(lm::DiffusionModel::kDipole))
    ->Arg(int(lm::DiffusionModel::kTabulated))
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
