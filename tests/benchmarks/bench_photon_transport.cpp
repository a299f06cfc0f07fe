// Photons per second of the Monte Carlo photon transport (acquire/photon_transport), semi-infinite
// slab, normal incidence, one channel: marble red (sigma_a 0.0021, sigma_s' 2.19 /mm, eta 1.5),
// potato red (0.0024, 0.68 /mm, eta 1.3), both isotropic as the library gives them, and soy milk
// blue (0.0034, sigma_s 0.456 /mm, g 0.832, eta 1.3: Henyey-Greenstein scattering). Reference:
// MCML 1.2 (github:bipy/MCML, gcc 12 -O3), timed on this project's 2-core VM on the same media, does
// 2.9e4 (marble), 7.6e4 (potato) and 5.1e4 (soy milk) photons per CPU-second, 17-19M interactions
// (notebooks_data/bench/photon_transport_bench.sh; an earlier comment here said 1.4e4 and 3.2e4,
// half of what it does here).
//
// items_per_second is photons per second: CPU time of the calling thread for threads=1 (the work
// runs on it), wall-clock time for threads=2 (UseRealTime; divide by 2 for photons per CPU-second).
// "image" adds the next-event camera image (128 x 128, 0.1 mm), which MCML does not compute.
// Run: <build>/tests/benchmarks/bench_photon_transport --benchmark_repetitions=5
//        --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <string>

#include "lucent/acquire/photon_transport.h"
#include "lucent/materials/material.h"

namespace la = lucent::acquire;

namespace {

enum Sample { kMarble = 0, kPotato = 1, kSoymilk = 2 };

const char* sample_name(int sample) {
  return sample == kMarble ? "marble" : sample == kPotato ? "potato" : "soymilk";
}

la::PhotonTransportOptions options_for(int sample, int threads, bool image) {
  la::PhotonTransportOptions o;
  const int channel = sample == kSoymilk ? 2 : 0;
  o.media[0] = lucent::materials::load_material(sample_name(sample)).medium(channel);
  o.channels = {true, false, false};
  // Eight batches: two threads share them evenly even though batch times vary (heavy-tailed walks).
  o.photons = 8 * la::kPhotonsPerBatch;
  o.threads = threads;
  o.image = image;
  return o;
}

void BM_PhotonTransport(benchmark::State& state) {
  const int sample = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  const bool image = state.range(2) != 0;
  la::PhotonTransportOptions o = options_for(sample, threads, image);
  double interactions = 0;
  for (auto _ : state) {
    const la::PhotonTransportResult result = la::simulate_photon_transport(o);
    interactions = result.channels[0].mean_interactions;
    benchmark::DoNotOptimize(result.channels[0].diffuse_reflectance.value);
    ++o.seed;  // fresh photons each iteration, same amount of work on average
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(o.photons));
  state.counters["interactions_per_photon"] = interactions;
  state.counters["interactions_per_second"] = benchmark::Counter(
      interactions * static_cast<double>(o.photons), benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel(std::string(sample_name(sample)) + (sample == kSoymilk ? " blue" : " red") +
                 (image ? ", image" : ""));
}

void photon_transport_arguments(benchmark::internal::Benchmark* b) {
  b->ArgNames({"sample", "threads", "image"});
  for (const int sample : {kMarble, kPotato, kSoymilk}) {
    for (const int image : {0, 1}) b->Args({sample, 1, image});
  }
}

void photon_transport_threaded_arguments(benchmark::internal::Benchmark* b) {
  b->ArgNames({"sample", "threads", "image"});
  for (const int sample : {kMarble, kPotato, kSoymilk}) {
    for (const int image : {0, 1}) b->Args({sample, 2, image});
  }
}

}  // namespace

BENCHMARK(BM_PhotonTransport)->Apply(photon_transport_arguments)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PhotonTransport)
    ->Apply(photon_transport_threaded_arguments)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
