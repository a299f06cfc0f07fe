// Evaluations per second of the standard and directional dipole, double and float, one thread.
// Run: build/release-or-ci/tests/benchmarks/bench_models --benchmark_repetitions=5
//        --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "lucent/materials/dipole.h"
#include "lucent/materials/directional_dipole.h"

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
BENCHMARK_MAIN();
