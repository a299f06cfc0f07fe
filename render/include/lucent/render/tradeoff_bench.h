// `lucent bench tradeoff`: the speed/accuracy map of every technique (issue 12, docs/DESIGN.md §8).
// Each scene (mesh, material, lighting) is rendered by the CPU reference at a converged sample
// count, then by every technique over a sweep of its knobs; each image's time and its error against
// the converged reference go to tradeoff.csv, the error-against-time curves to tradeoff.png / .svg,
// and the Pareto fronts and the times relative to the radiance maps at equal error to
// tradeoff_summary.md.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

namespace lucent::render {

/// How many knob settings each technique is run at.
enum class TradeoffSweep {
  kFull,   ///< every knob on the first scene, a short sweep on the others (the shipped map)
  kShort,  ///< a few settings per technique on every scene
  kTiny,   ///< one or two cheap settings per technique (ctest)
};
TradeoffSweep parse_tradeoff_sweep(const std::string& text);  ///< full | short | tiny

/// What every image is held to: the path tracer (the medium itself: the error includes each
/// model's) or the converged CPU reference of the same BSSRDF model (the pipeline's error alone).
enum class TradeoffTruth { kPathtrace, kReference };
TradeoffTruth parse_tradeoff_truth(const std::string& text);

struct TradeoffBenchOptions {
  std::filesystem::path out_dir = ".";  ///< --out-dir (default: the current folder)
  /// MESH/MATERIAL/LIGHTING[/SIZE_MM], LIGHTING one of directional, point, env (a procedural sky
  /// of `env_lights` importance-sampled lights), SIZE_MM the object's size (default 100). The first
  /// scene gets the full sweep. Every technique renders as the CLI does by default: the single
  /// scattering, the angular and the shape's factors on where it has them.
  std::vector<std::string> scenes = {"sphere/marble/directional", "sphere/potato/point",
                                     "sphere/skin1/env",          "sphere/ketchup/directional",
                                     "bunny/marble/point",        "dragon:3/skin1/env"};
  TradeoffSweep sweep = TradeoffSweep::kFull;
  int size = 64;                      ///< image, pixels square
  TradeoffTruth truth = TradeoffTruth::kPathtrace;
  int truth_samples = 2048;           ///< paths per pixel of the path-traced truth
  int reference_samples = 8192;       ///< probes per pixel of the converged reference
  int env_lights = 8;                 ///< lights standing for the environment map
  int threads = 0;                    ///< the reference's threads (0: all)
};

/// One image: a technique at one setting on one scene.
struct TradeoffRow {
  std::string scene, mesh, material, lighting, technique, model, setting;
  long triangles = 0;
  double frame_ms = 0;     ///< steady-state time per frame (reference: the whole render)
  double image_ms = 0;     ///< from nothing to this image: setup, precomputation, every frame
  double converge_ms = 0;  ///< to the setting's converged image (maps: within 2% of its last)
  int frames = 1;          ///< accumulated into this image
  double relative_rmse = 0;           ///< against the converged reference
  double mean_ratio[3] = {0, 0, 0};   ///< per channel, image mean / reference mean
  double scaled_rmse = 0;             ///< after the least-squares scale (compare_scaled)
  double scale = 0, correlation = 0;
  /// What the map plots: relative_rmse, or scaled_rmse for techniques that are right only up to
  /// a scale (sh).
  double error() const;
  bool scale_only() const;  ///< the registry's technique is not physically based
};

/// The rows of one technique (or all, technique empty) not beaten by another row in both time
/// (`use_frame_time`: frame_ms, else image_ms) and error, sorted by time.
std::vector<TradeoffRow> pareto_front(const std::vector<TradeoffRow>& rows,
                                      const std::string& technique, bool use_frame_time);

/// The maps' time at the error `error`, interpolated log-log along their Pareto front; a negative
/// value when the front does not reach that error (no equal-error point: nothing is
/// extrapolated).
double maps_time_at_error(const std::vector<TradeoffRow>& maps_front, double error,
                          bool use_frame_time);

/// The CSV (header + rows), and the summary's Markdown (Pareto fronts, equal-error ratios).
std::string tradeoff_csv(const std::vector<TradeoffRow>& rows);
/// `reference_samples`: the converged reference's probes per pixel (its noise is estimated from
/// the reference rows).
/// `truth`: what the error is against, in words; `reference_samples` 0 when it is not the
/// reference.
std::string tradeoff_summary(const std::vector<TradeoffRow>& rows, const std::string& machine,
                             const std::string& truth, int reference_samples);

/// Runs the sweep (progress lines to `log`), writes tradeoff.csv, tradeoff.png, tradeoff.svg and
/// tradeoff_summary.md into out_dir (each atomically). Returns the rows.
std::vector<TradeoffRow> run_tradeoff_bench(const TradeoffBenchOptions& options, std::ostream& log);

}  // namespace lucent::render
