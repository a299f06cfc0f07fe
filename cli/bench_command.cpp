// `lucent bench`: the speed/accuracy sweeps (DESIGN §8), written to notebooks_data/bench/.
#include <iostream>
#include <memory>

#include "commands.h"
#include "lucent/fit/fit_bench.h"

namespace lucent::cli {

void register_bench_command(CLI::App& app) {
  CLI::App* bench =
      app.add_subcommand("bench", "Speed against accuracy sweeps; CSV and plots to --out-dir");
  bench->require_subcommand(1);
  auto options = std::make_shared<fit::FitBenchOptions>();
  CLI::App* fit_cmd = bench->add_subcommand(
      "fit",
      "Sweep --quality, model and derivatives over captures with known truth: median fit time "
      "and parameter error -> fit_tradeoff.csv and fit_tradeoff.png");
  fit_cmd->add_option("--out-dir", options->out_dir, "output folder")->capture_default_str();
  fit_cmd
      ->add_option("--sample", options->sample_capture,
                   "bundled Monte Carlo capture (its truth.json beside it)")
      ->capture_default_str();
  fit_cmd->add_option("--repeats", options->repeats, "timed fits per setting (median reported)")
      ->capture_default_str();
  fit_cmd->add_option("--size", options->size_px, "simulated captures' size, pixels")
      ->capture_default_str();
  fit_cmd->callback([options] {
    const int n = fit::run_fit_bench(*options, std::cout);
    std::cout << "bench fit: " << n << " settings; wrote "
              << (options->out_dir / "fit_tradeoff.csv").string() << " and fit_tradeoff.png\n";
  });
}

}  // namespace lucent::cli
