// `lucent tabulate`: builds the transport table of the tabulated model (white Monte Carlo), or a
// shard of it for a cluster's job array, or merges shards.
#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>
#include <tuple>

#include "batch.h"
#include "commands.h"
#include "lucent/acquire/tabulate.h"
#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/core/json_file.h"
#include "lucent/materials/profile_table.h"
#include "progress.h"
#include "validators.h"

namespace lucent::cli {
namespace {

struct TabulateArguments {
  std::string output;
  std::string eta = "1.0,1.1,1.2,1.3,1.4,1.5,1.6";
  std::string g = "0";
  std::string incidence = "0";
  int phi_bins = 0;  // 0: 1 at normal incidence, the oblique grid's otherwise
  std::string shard;
  std::vector<std::string> merge;
  bool quiet = false;
  acquire::TabulateOptions options;
};

std::vector<double> parse_list(const std::string& text, const std::string& option) {
  std::vector<double> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      std::size_t used = 0;
      const double v = std::stod(item, &used);
      if (used != item.size() || !std::isfinite(v)) throw std::invalid_argument(item);
      out.push_back(v);
    } catch (const std::exception&) {
      throw Error(option + ": expected a comma-separated list of numbers, got '" + item + "'");
    }
  }
  return out;
}


// Shards (and finished tables of other slices) merged into one table file; its slice count.
std::size_t merge_table_files(const std::vector<std::string>& inputs, const std::string& output) {
  std::vector<materials::TransportTable> parts;
  for (const std::string& p : inputs) parts.push_back(materials::read_transport_table(p));
  const materials::TransportTable table = materials::merge_transport_tables(parts);
  materials::write_transport_table(table, output);
  return table.slices.size();
}

void run(TabulateArguments& args) {
  check_output_file(args.output, "", "-o");  // before hours of transport, not after
  if (!args.merge.empty()) {
    const std::size_t slices = merge_table_files(args.merge, args.output);
    if (!args.quiet)
      std::cout << "merged " << args.merge.size() << " shards into " << args.output << " ("
                << slices << " slices)\n";
    return;
  }
  acquire::TabulateOptions& o = args.options;
  o.eta = parse_list(args.eta, "--eta");
  o.g = parse_list(args.g, "--g");
  o.incidence_deg = parse_list(args.incidence, "--incidence-deg");
  const bool oblique = o.incidence_deg.size() > 1 || o.incidence_deg.front() != 0;
  if (oblique) {
    // An oblique table: the oblique grid (coarser in rho, azimuth wedges).
    o.grid = materials::default_oblique_grid();
  }
  if (args.phi_bins > 0) o.grid.phi_bins = args.phi_bins;
  if (!args.shard.empty())
    std::tie(o.shard_index, o.shard_count) = parse_shard(args.shard, "--shard");
  // The white runs' photons are counted (the direct runs' are short).
  ProgressLine line("tabulate", "white-run photons", args.quiet);
  const auto progress = [&](std::uint64_t done, std::uint64_t total) { line.update(done, total); };
  const materials::TransportTable table = acquire::tabulate_transport(o, progress);
  materials::write_transport_table(table, args.output);
  const double seconds = line.seconds();
  line.finish();
  if (!args.quiet) {
    std::cout << "wrote " << (table.partial ? "shard " + table.shard + " " : std::string())
              << args.output << ": " << table.slice_axes.size() << " slices (eta x g"
              << (oblique ? " x incidence" : "") << "), " << table.grid.u.size() << " albedos x "
              << (oblique ? std::to_string(table.grid.phi_bins) + " azimuths x " : std::string())
              << table.grid.rho_bins() << " radii, " << std::uint64_t(table.slice_axes.front()[2]) << " photons per slice, in "
              << duration_text(seconds) << '\n';
  }
}

}  // namespace

void register_tabulate_command(CLI::App& app) {
  auto args = std::make_shared<TabulateArguments>();
  auto& o = args->options;
  CLI::App* cmd = app.add_subcommand(
      "tabulate",
      "Builds the transport table of --model tabulated: the radial exitance and normal radiance "
      "of a semi-infinite slab under a normal pencil beam, per unit power entering, in optical "
      "units (r sigma_t', alpha'), per eta and g, by white Monte Carlo (one absorption-free run "
      "serves every albedo). Deterministic for a seed; --shard I/N builds a part for a job "
      "array, --merge joins the parts.");
  cmd->add_option("-o,--output", args->output, "table file to write (atomically)")->required();
  cmd->add_option("--eta", args->eta, "relative indices, increasing, in [1, 2.5]")
      ->capture_default_str();
  cmd->add_option("--g", args->g, "Henyey-Greenstein g values, increasing, in [0, 0.99]")
      ->capture_default_str();
  cmd->add_option("--incidence-deg", args->incidence,
                  "beam angles from the normal (degrees, increasing, in [0, 85]); any > 0 builds "
                  "an oblique table (2D profile in rho and azimuth, for 2D captures at that "
                  "incidence: lucent fit --oblique-table)")
      ->capture_default_str();
  cmd->add_option("--phi-bins", args->phi_bins,
                  "azimuth wedges over [0, pi] (default: 1, or 12 for an oblique table)")
      ->check(CLI::Range(1, 360));
  cmd->add_option("--photons", o.photons, "photons per slice")->capture_default_str();
  cmd->add_option("--white-photons", o.white_photons,
                  "photons of the white run (alpha' >= 0.4) per slice, fewer than --photons to "
                  "make high-g slices affordable (default: --photons)");
  cmd->add_option("--seed", o.seed, "random seed (same table for any --threads or sharding)")
      ->transform(seed_value())
      ->capture_default_str();
  cmd->add_option("--threads", o.threads, "worker threads (0 = all cores)")
      ->transform(thread_count())
      ->capture_default_str();
  cmd->add_option("--groups", o.groups, "independent photon groups per slice (standard errors)")
      ->capture_default_str();
  cmd->add_option("--max-path", o.max_path, "paths cut at this length, units of 1/sigma_s'")
      ->capture_default_str();
  cmd->add_option("--shard", args->shard, "build shard I of N (0-based) as a partial table");
  cmd->add_option("--merge", args->merge, "merge these tables into -o instead: the shards of one build, and finished tables of other slices (same grid)")
      ->expected(1, -1);
  cmd->add_flag("-q,--quiet", args->quiet, "no progress or summary");
  cmd->callback([args] { run(*args); });
}

// `lucent merge`: the shards of a job array, put together: transport tables (.lut, as tabulate
// --merge) or batch-fit summaries (.json, lucent fit --batch --shard).
void register_merge_command(CLI::App& app) {
  auto output = std::make_shared<std::string>();
  auto inputs = std::make_shared<std::vector<std::string>>();
  CLI::App* cmd = app.add_subcommand(
      "merge",
      "Joins the shards of a job array: transport tables (.lut from lucent tabulate --shard) or "
      "batch summaries (.json from lucent fit --batch --shard). Every shard exactly once; the "
      "result equals one unsharded run.");
  cmd->add_option("inputs", *inputs, "the shards")->required()->expected(1, -1);
  cmd->add_option("-o,--output", *output, "the merged file")->required();
  cmd->callback([output, inputs] {
    const bool tables = std::filesystem::path(inputs->front()).extension() == ".lut";
    check_output_file(*output, tables ? ".lut" : ".json", "-o");
    if (tables) {
      merge_table_files(*inputs, *output);
    } else {
      std::vector<nlohmann::json> parts;
      for (const std::string& p : *inputs) parts.push_back(read_json_file(p));
      const nlohmann::json merged = merge_batch_summaries(parts, *inputs);
      write_file_atomically(*output, merged.dump(2) + "\n");
    }
    std::cout << "merged " << inputs->size() << " shards into " << *output << '\n';
  });
}

}  // namespace lucent::cli
