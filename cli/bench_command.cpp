// `lucent bench`: the speed/accuracy sweeps (docs/DESIGN.md §8), written to the folder given
// (--out-dir, --out; default the current folder: notebooks_data/bench/ holds the shipped runs,
// which a run elsewhere must not overwrite).
#include <cstdio>
#include <iostream>
#include <memory>

#include "commands.h"
#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/fit/fit_bench.h"
#include "lucent/render/render_bench.h"
#include "lucent/render/tradeoff_bench.h"
#include "technique_flags.h"

namespace lucent::cli {
namespace {

// `lucent bench fit`: the fit's quality, model and derivatives swept over captures with known
// truth.
void register_fit_bench(CLI::App* bench) {
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
    check_output_folder(options->out_dir / "fit_tradeoff.csv");  // before the sweep, not after
    const int n = fit::run_fit_bench(*options, std::cout);
    std::cout << "bench fit: " << n << " settings; wrote "
              << (options->out_dir / "fit_tradeoff.csv").string() << " and fit_tradeoff.png\n";
  });
}

// `lucent bench render`: per-stage times of the radiance-map technique.
void register_render_bench(CLI::App* bench) {
  auto render_options = std::make_shared<render::RenderBenchOptions>();
  CLI::App* render_cmd = bench->add_subcommand(
      "render",
      "Per-stage times (light map, radiance map, mip blur, final) of the radiance-map technique at "
      "the seed's settings on the bunny and dragon:4..2 -> render.csv");
  auto& rs = render_options->settings;
  render_cmd->add_option("--out", render_options->out_csv, "CSV to write")->capture_default_str();
  render_cmd->add_option("--meshes", render_options->meshes, "meshes to time")->capture_default_str();
  render_cmd->add_option("--frames", render_options->frames, "frames timed per mesh")
      ->capture_default_str();
  render_cmd->add_option("--size", render_options->size, "image size, pixels")->capture_default_str();
  add_maps_sampling_flags(render_cmd, rs);
  auto selections = std::make_shared<std::vector<std::string>>(
      std::vector<std::string>{"strata", "nearest"});
  render_cmd->add_option("--disc-selection", *selections, "disc selections to time (rows each)")
      ->capture_default_str();
  render_cmd->callback([render_options, selections, render_cmd] {
    warn_deprecated_flags(render_cmd);
    check_output_folder(render_options->out_csv);  // before the sweep, not after
    render_options->disc_selections.clear();
    for (const auto& text : *selections) {
      render_options->disc_selections.push_back(render::parse_disc_selection(text));
    }
    const int n = render::run_render_bench(*render_options, std::cout);
    std::cout << "bench render: " << n << " meshes; wrote " << render_options->out_csv.string()
              << "\n";
  });
}

// `lucent bench fur`: the fur tile's precompute and draw times per shell count.
void register_fur_bench(CLI::App* bench) {
  auto fur_options = std::make_shared<render::FurBenchOptions>();
  auto fur_size = std::make_shared<std::string>("1280x1024");
  CLI::App* fur_cmd = bench->add_subcommand(
      "fur",
      "Time the fur tile (Klotzli & Olano) at the seed's 1280 x 1024 for each shell count: the CPU "
      "precompute and the median draw per frame -> fur.csv");
  fur_cmd->add_option("--out", fur_options->out_csv, "CSV to write")->capture_default_str();
  fur_cmd->add_option("--shells", fur_options->shells, "shell counts to time (a row each)")
      ->delimiter(',')
      ->capture_default_str();
  fur_cmd->add_option("--texels", fur_options->texels, "the tile's texels across")
      ->check(CLI::Range(2, 4096))
      ->capture_default_str();
  fur_cmd->add_option("--frames", fur_options->frames, "frames timed per row (median reported)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  fur_cmd->add_option("--size", *fur_size, "WxH, pixels")->capture_default_str();
  fur_cmd->callback([fur_options, fur_size] {
    check_output_folder(fur_options->out_csv);
    int w = 0, h = 0, end = 0;
    if (std::sscanf(fur_size->c_str(), "%dx%d%n", &w, &h, &end) != 2 ||
        end != int(fur_size->size()) || w < 1 || h < 1 || w > 16384 || h > 16384) {
      throw lucent::Error("--size: expected WxH, whole numbers 1..16384, got '" + *fur_size + "'");
    }
    fur_options->width = w;
    fur_options->height = h;
    for (const int s : fur_options->shells) {
      if (s < 1 || s > 1024) {
        throw lucent::Error("--shells: expected counts in 1..1024, got " + std::to_string(s));
      }
    }
    const int n = render::run_fur_bench(*fur_options, std::cout);
    std::cout << "bench fur: " << n << " rows; wrote " << fur_options->out_csv.string() << '\n';
  });
}

// `lucent bench hierarchical`: seed 004's modes, links and memory beside its Table 3.
void register_hierarchical_bench(CLI::App* bench) {
  auto o = std::make_shared<render::HierarchicalBenchOptions>();
  CLI::App* cmd = bench->add_subcommand(
      "hierarchical",
      "Seed 004's modes on the CPU (Mertens et al.): linking, render-mode frames (a light "
      "turning), "
      "on-the-fly and incremental frames of a deforming mesh, links and their memory, for lucent's "
      "defaults and the seed's Table 3 setting, beside the paper's figures; and links per triangle "
      "against the error from the all-pairs solution -> hierarchical.csv, hierarchical_error.csv, "
      "hierarchical.png");
  cmd->add_option("--out-dir", o->out_dir, "folder for the CSVs and the figure")
      ->capture_default_str();
  cmd->add_option("--meshes", o->meshes, "meshes to time (NAME@T: simplified to T triangles)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--threads", o->threads, "thread counts to time (0: every core)")
      ->delimiter(',')
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  cmd->add_option("--frames", o->frames, "frames timed per mode (median reported)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--incremental-budget", o->incremental_budget,
                  "incremental frames: factor evaluations per frame")
      ->check(CLI::Range(1L, 1000000000L))
      ->capture_default_str();
  cmd->add_option("--error-mesh", o->error_mesh, "mesh of the links-against-error sweep")
      ->capture_default_str();
  cmd->add_option("--material", o->material, "bundled material or file")->capture_default_str();
  cmd->callback([o] {
    check_output_folder(o->out_dir / "hierarchical.csv");
    const auto result = render::run_hierarchical_bench(*o, std::cout);
    std::cout << "bench hierarchical: " << result.rows << " rows, " << result.error_rows
              << " error rows; wrote hierarchical.csv, hierarchical_error.csv and "
                 "hierarchical.png in "
              << o->out_dir.string() << '\n';
  });
}

// `lucent bench tradeoff`: every technique's knobs swept against a converged CPU reference.
void register_tradeoff_bench(CLI::App* bench) {
  auto tradeoff = std::make_shared<render::TradeoffBenchOptions>();
  auto sweep = std::make_shared<std::string>("full");
  auto truth = std::make_shared<std::string>("pathtrace");
  CLI::App* tradeoff_cmd = bench->add_subcommand(
      "tradeoff",
      "Every technique (maps with each model, sh, hierarchical, the reference) over a sweep of "
      "its knobs on a set of scenes, against a converged CPU reference: time per frame, time to "
      "the image and to convergence, relative RMSE (sh: after the best scale, with correlation) "
      "-> tradeoff.csv, tradeoff.png/.svg and tradeoff_summary.md in --out-dir");
  tradeoff_cmd->add_option("--out-dir", tradeoff->out_dir, "output folder")->capture_default_str();
  tradeoff_cmd
      ->add_option("--scenes", tradeoff->scenes,
                   "MESH/MATERIAL/LIGHTING[/SIZE_MM], LIGHTING directional, point or env (a "
                   "procedural sky), SIZE_MM the object's size (default 100); the first gets the "
                   "full sweep")
      ->delimiter(',')
      ->capture_default_str();
  tradeoff_cmd->add_option("--sweep", *sweep, "full, short or tiny (knob settings per technique)")
      ->capture_default_str();
  tradeoff_cmd->add_option("--size", tradeoff->size, "image size, pixels square")
      ->capture_default_str();
  tradeoff_cmd
      ->add_option("--truth", *truth,
                   "pathtrace (the medium itself: each model's error included) or reference (the "
                   "converged reference of the same model: the pipeline's error alone)")
      ->capture_default_str();
  tradeoff_cmd
      ->add_option("--truth-samples", tradeoff->truth_samples,
                   "paths per pixel of the path-traced truth")
      ->capture_default_str();
  tradeoff_cmd
      ->add_option("--reference-samples", tradeoff->reference_samples,
                   "probes per pixel of the converged reference (--truth reference)")
      ->capture_default_str();
  tradeoff_cmd->add_option("--env-lights", tradeoff->env_lights, "lights for the environment map")
      ->capture_default_str();
  tradeoff_cmd->add_option("--threads", tradeoff->threads, "the reference's threads (0: all)")
      ->capture_default_str();
  tradeoff_cmd->callback([tradeoff, sweep, truth] {
    tradeoff->sweep = render::parse_tradeoff_sweep(*sweep);
    tradeoff->truth = render::parse_tradeoff_truth(*truth);
    check_output_folder(tradeoff->out_dir / "tradeoff.csv");  // before the sweep, not after
    const auto rows = render::run_tradeoff_bench(*tradeoff, std::cout);
    std::cout << "bench tradeoff: " << rows.size() << " images; wrote "
              << (tradeoff->out_dir / "tradeoff.csv").string()
              << ", tradeoff.png, tradeoff.svg and tradeoff_summary.md\n";
  });
}

}  // namespace

void register_bench_command(CLI::App& app) {
  CLI::App* bench =
      app.add_subcommand("bench", "Speed against accuracy sweeps; CSV and plots to --out-dir");
  bench->require_subcommand(1);
  register_fit_bench(bench);
  register_render_bench(bench);
  register_fur_bench(bench);
  register_hierarchical_bench(bench);
  register_tradeoff_bench(bench);
}

}  // namespace lucent::cli
