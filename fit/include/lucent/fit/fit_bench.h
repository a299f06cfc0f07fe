// `lucent bench fit`: the fit's speed against its accuracy (docs/DESIGN.md §8). Each setting
// (quality, model, derivatives) is run on captures whose truth is known, and its median solve time
// and parameter errors go to a CSV and a plot of the trade curve.
#pragma once

#include <filesystem>
#include <iosfwd>

namespace lucent::fit {

struct FitBenchOptions {
  std::filesystem::path out_dir = ".";  ///< fit_tradeoff.csv and .png go here (--out-dir)
  std::filesystem::path sample_capture = "notebooks_data/captures/marble_0deg/capture.json";
  int repeats = 5;   ///< timed fits per setting; the median is reported
  int size_px = 64;  ///< simulated captures' size
};

/// Runs the sweep; progress lines go to `log`. Returns the number of settings measured.
int run_fit_bench(const FitBenchOptions& options, std::ostream& log);

}  // namespace lucent::fit
