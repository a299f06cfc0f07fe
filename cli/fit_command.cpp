// `lucent fit`: profiles in, a material file out.
#include <charconv>
#include <cmath>
#include <iostream>
#include <memory>

#include "batch.h"
#include "commands.h"
#include "fit_beam.h"
#include "fit_tables.h"
#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/core/json_file.h"
#include "lucent/fit/fit.h"
#include "lucent/fit/fit_plot.h"
#include "lucent/materials/transport_table.h"
#include "progress.h"
#include "validators.h"

namespace lucent::cli {
namespace {

struct FitArguments {
  std::vector<std::string> inputs;
  std::string output;
  std::string model = "auto";
  std::string loss = "none";
  std::string quality = "balanced";
  std::string plot, report, name;
  double exclude_radius_mm = -1;
  CLI::Option* exclude_option = nullptr;
  CLI::Option* ior_option = nullptr;
  double ior = 0;
  double g = 0;
  std::string table, oblique_table, batch, shard;
  bool quiet = false;        // batch rows: no per-row summary on stdout
  bool no_progress = false;  // -q: no progress line on stderr (batch rows never show one)
  bool row_ior = false;      // a batch row gave ior
  std::uint64_t oblique_photons = 1'000'000;
  std::uint64_t table_photons = 1'000'000;
  std::uint64_t slab_photons = 200'000;
  double thickness_mm = 0;  // 0: not given
  double beam_sigma_mm = 0;  // 0: not given
  std::string beam_image;
  double beam_pixel_mm = 0;  // 0: the first input's pixel pitch
  bool fit_ior = false, relative = false, json = false, allow_unconverged = false;
  bool fit_thickness = false;
  bool allow_outside = false;  // --batch: row outputs outside the manifest's folder
  bool plot_log_r = false;  // --plot-log-r
};

fit::FitOptions to_options(const FitArguments& a) {
  fit::FitOptions o;
  o.model = fit::parse_fit_model(a.model);
  if (!(a.g >= 0 && a.g <= 0.99)) throw Error("--g: expected a Henyey-Greenstein g in [0, 0.99]");
  o.g = a.g;
  o.quality = fit::parse_quality(a.quality);
  if (a.loss == "none") {
    o.loss = fit::LossKind::kNone;
  } else {
    const auto colon = a.loss.find(':');
    const std::string kind = a.loss.substr(0, colon);
    if (kind == "huber")
      o.loss = fit::LossKind::kHuber;
    else if (kind == "cauchy")
      o.loss = fit::LossKind::kCauchy;
    else
      throw Error("--loss: expected none, huber:S or cauchy:S, got '" + a.loss + "'");
    if (colon != std::string::npos) {
      const std::string scale = a.loss.substr(colon + 1);
      const auto [end, ec] =
          std::from_chars(scale.data(), scale.data() + scale.size(), o.loss_scale);
      if (ec != std::errc() || end != scale.data() + scale.size() ||
          !(o.loss_scale > 0 && o.loss_scale <= 1e6)) {
        throw Error("--loss: the scale S in '" + a.loss +
                    "' must be a number in (0, 1e6] standard errors");
      }
    }
  }
  // Given or not is what counts (the validators have checked the values): no value falls back.
  if (a.exclude_option && a.exclude_option->count() > 0) o.exclude_radius_mm = a.exclude_radius_mm;
  if (a.thickness_mm > 0) o.thickness_mm = a.thickness_mm;
  o.fit_thickness = a.fit_thickness;
  if (o.fit_thickness && o.thickness_mm)  // before any slab table is built
    throw Error("--fit-thickness: the thickness is either given (--thickness-mm) or fitted, not both");
  o.beam_sigma_mm = a.beam_sigma_mm;
  if (a.row_ior || (a.ior_option && a.ior_option->count() > 0)) {
    if (!(a.ior > 0 && a.ior <= 4)) throw Error("--ior: expected a relative index in (0, 4]");
    o.ior = a.ior;
  }
  o.fit_ior = a.fit_ior;
  if (a.relative) o.relative = true;
  o.allow_unconverged = a.allow_unconverged;
  return o;
}

// Stage 1 of a fit: where the outputs go is checked before the fit (they are written together at
// the end).
void check_fit_outputs(const FitArguments& a) {
  check_output_file(a.output, ".json", "-o");
  if (!a.plot.empty()) {
    check_output_file(a.plot, "", "--plot");
    fit::check_fit_plot_path(a.plot, "--plot");
  }
  if (!a.report.empty()) check_output_file(a.report, ".json", "--report");
  check_distinct_outputs({{"-o", a.output}, {"--plot", a.plot}, {"--report", a.report}});
}

// Stage 2 of a fit: the profiles read, each with an index from itself or the options, and the
// beam image applied to them.
std::vector<fit::ProfileData> load_fit_inputs(const FitArguments& a,
                                              const fit::FitOptions& options) {
  std::vector<fit::ProfileData> data;
  for (const std::string& input : a.inputs) {
    data.push_back(fit::load_profile_data(input));
    if (!data.back().eta && !options.ior && !options.fit_ior) {
      throw Error("--ior: required with " + input +
                  ", which carries no index (no ior= or eta= "
                  "in its comment lines)");
    }
  }
  if (!a.beam_image.empty()) {
    if (a.beam_sigma_mm > 0)
      throw Error("--beam-image: the beam is given either as an image or as --beam-sigma-mm");
    use_beam_image(data, a.beam_image, a.beam_pixel_mm);
  }
  return data;
}

// The tables a fit's options point to; they live as long as the options are used.
struct FitTables {
  materials::TransportTable given;  // --table
  std::optional<materials::TransportTable> oblique;
};

// Stage 3 of a fit: the transport tables it uses (given, cached or built now) set in `options`.
void choose_fit_tables(const FitArguments& a, const std::vector<fit::ProfileData>& data,
                       fit::FitOptions& options, FitTables& tables) {
  if (!a.table.empty()) {
    materials::TransportTable& table = tables.given;
    table = materials::read_transport_table(a.table);
    // Given on purpose, so a table that cannot serve a radial fit is an error, not a quiet fall
    // back to the diffusion models.
    if (table.partial)
      throw Error("--table " + a.table + ": a shard of a table build (kind partial): merge the "
                  "shards first (lucent tabulate --merge)");
    if (table.grid.phi_bins > 1)
      throw Error("--table " + a.table + ": an oblique (2D) table: give it as --oblique-table");
    if (table.slab())
      throw Error("--table " + a.table + ": a slab's table: lucent fit builds those itself "
                  "(--thickness-mm)");
    options.table = &table;
  }
  if (const materials::TransportTable* radial =
          radial_table_for(data, options, a.table_photons, a.json || a.quiet || a.no_progress))
    options.table = radial;
  options.slab = slab_nodes_for(data, options, a.slab_photons, a.json || a.quiet || a.no_progress);
  tables.oblique = oblique_table_for(data, options, a.oblique_table, a.oblique_photons, a.json);
  if (tables.oblique) options.oblique_table = &*tables.oblique;
}

// Stage 5 of a fit: the plot, the report and the material file, each written atomically.
void write_fit_outputs(const FitArguments& a, const fit::FitResult& result,
                       const std::vector<fit::ProfileData>& data, const fit::FitOptions& options,
                       const materials::Material& material) {
  if (!a.plot.empty()) {
    fit::FitPlotOptions plot_options;
    plot_options.log_r = a.plot_log_r;
    // The plot's model is the fit's: the thickness the options gave every input included.
    fit::ProfileData plotted = data.front();
    if (options.thickness_mm) plotted.thickness_mm = options.thickness_mm;
    if (result.thickness && std::isfinite(result.thickness->thickness_mm))
      plotted.thickness_mm = result.thickness->thickness_mm;
    fit::write_fit_plot(a.plot, result, plotted, plot_options);
  }
  if (!a.report.empty()) {
    const nlohmann::json report = fit::fit_report(result, data, options);
    check_finite_json(report, a.report);
    write_file_atomically(a.report, report.dump(2) + "\n");
  }
  materials::write_material(a.output, material);
}

// A fit's summary as text: the chosen model's coefficients per channel, the thickness, how g
// moves the answer, the cheapest adequate model, notes and warnings.
void print_fit_summary(const FitArguments& a, const fit::FitResult& result) {
  const fit::ModelFit& f = result.chosen;
  const char* names[3] = {"R", "G", "B"};
  std::cout << "fitted " << fit::to_string(f.model) << " (" << result.reason << ")\n";
  for (int c = 0; c < 3; ++c) {
    const fit::ChannelFit& ch = f.channels[c];
    if (ch.samples == 0) continue;
    std::cout << "  " << names[c] << ": sigma_a = " << ch.sigma_a << " +- " << ch.sd_sigma_a
              << " /mm, sigma_s' = " << ch.sigma_s_reduced << " +- " << ch.sd_sigma_s_reduced
              << " /mm (total SD; statistical " << ch.sd_stat_sigma_a << ", "
              << ch.sd_stat_sigma_s_reduced << "; systematic " << ch.sd_sys_sigma_a << ", "
              << ch.sd_sys_sigma_s_reduced << "), " << ch.samples << " samples over "
              << ch.exclude_radius_mm << ".." << ch.range_end_mm << " mm, reduced chi^2 "
              << ch.reduced_chi2 << "\n";
  }
  if (result.thickness) {
    const fit::ThicknessFit& t = *result.thickness;
    if (t.determined)
      std::cout << "  thickness: " << t.thickness_mm << " mm (1 SD " << t.lower_mm << ".."
                << t.upper_mm << " mm)\n";
    else if (!std::isfinite(t.upper_mm))
      std::cout << "  thickness: undetermined, any above " << t.lower_mm
                << " mm fits (the data look semi-infinite)\n";
    else
      std::cout << "  thickness: undetermined, any below " << t.upper_mm << " mm fits\n";
  }
  if (!result.g_09.empty()) {
    std::cout << "  assumed g = " << result.g << "; at g = " << result.g_other
              << " the answer would be:";
    for (int c = 0; c < 3; ++c) {
      if (f.channels[c].samples == 0) continue;
      std::cout << " " << names[c] << " sigma_a " << result.g_09[c][0] << ", sigma_s' "
                << result.g_09[c][1] << ";";
    }
    std::cout << " (radial data cannot tell g from sigma_s)\n";
  }
  if (result.adequate_model == "none")
    std::cout << "  no cheaper model is adequate (within "
              << 100 * fit::ModelAdequacy::kBar << "% of the " << fit::to_string(f.model)
              << " profile over most of the data); without its table a renderer uses "
              << result.fallback_model << ", the closest\n";
  else if (!result.adequate_model.empty())
    std::cout << "  cheapest adequate model for rendering (within "
              << 100 * fit::ModelAdequacy::kBar << "% of the " << fit::to_string(f.model)
              << " profile): " << result.adequate_model << '\n';
  for (const std::string& note : result.notes) std::cout << "  note: " << note << '\n';
  for (const std::string& w : result.warnings) warn("lucent fit: warning: " + w);
  std::cout << "wrote " << a.output << '\n';
}

// Stage 6 of a fit: what it says; a batch row only its warnings, --json the report.
void report_fit(const FitArguments& a, const fit::FitResult& result,
                const std::vector<fit::ProfileData>& data, const fit::FitOptions& options) {
  if (a.quiet) {
    for (const std::string& w : result.warnings)
      warn("lucent fit: " + a.output + ": warning: " + w);
    return;
  }
  if (a.json) {
    nlohmann::json j = fit::fit_report(result, data, options);
    j["output"] = a.output;
    std::cout << j.dump(2) << '\n';
    return;
  }
  print_fit_summary(a, result);
}

materials::Material run(const FitArguments& a) {
  fit::FitOptions options = to_options(a);
  check_fit_outputs(a);
  const std::vector<fit::ProfileData> data = load_fit_inputs(a, options);
  FitTables tables;
  choose_fit_tables(a, data, options, tables);
  // Stage 4: the fit itself.
  StageProgress progress("fit", a.quiet || a.no_progress);
  options.progress = [&](const std::string& stage, double done) { progress.stage(stage, done); };
  const fit::FitResult result = fit::fit_profiles(data, options);
  progress.finish();
  std::string name = a.name;
  if (name.empty()) name = std::filesystem::path(a.output).stem().string();
  const materials::Material material = fit::fitted_material(result, data, options, name);
  // Everything is computed before anything is written.
  write_fit_outputs(a, result, data, options, material);
  report_fit(a, result, data, options);
  return material;
}

// --batch: every manifest row (or this shard's: rows i with i mod N = I) fitted like one `lucent
// fit` with the row's options over the command line's; a row that fails is recorded, not fatal.
// -o is the summary (JSON); the exit status is 1 when any row failed.
void run_batch(const FitArguments& a) {
  if (!a.inputs.empty())
    throw Error("--batch: give the profiles in the manifest, not as arguments");
  check_output_file(a.output, ".json", "-o");
  const auto [shard, shards] = a.shard.empty() ? std::pair{0, 1} : parse_shard(a.shard, "--shard");
  const std::vector<BatchRow> rows = read_batch_manifest(a.batch);
  plan_batch_outputs(rows, a.batch, a.output, a.allow_outside);
  std::vector<BatchOutcome> outcomes;
  int failed = 0;
  std::uint64_t mine = 0;
  for (const BatchRow& row : rows) mine += int(row.index % std::size_t(shards)) == shard;
  ProgressLine progress("fit --batch", "rows", a.no_progress);
  for (const BatchRow& row : rows) {
    if (int(row.index % std::size_t(shards)) != shard) continue;
    BatchOutcome o;
    o.row = row;
    try {
      FitArguments r = a;
      r.inputs = {row.input};
      r.output = row.output;
      r.quiet = true;
      r.json = false;
      r.plot.clear(), r.report.clear();
      if (row.options.count("model")) r.model = row.options.at("model");
      if (row.options.count("name")) r.name = row.options.at("name");
      const auto number = [&](const char* column) {
        const std::string& text = row.options.at(column);
        std::size_t used = 0;
        double v = 0;
        try {
          v = std::stod(text, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used != text.size() || !std::isfinite(v))
          throw Error(a.batch + ": row " + std::to_string(row.index + 1) + ": column '" + column +
                      "': expected a number, got '" + text + "'");
        return v;
      };
      if (row.options.count("g")) r.g = number("g");
      if (row.options.count("ior")) {
        r.ior = number("ior");
        r.ior_option = nullptr;
        r.row_ior = true;
      }
      o.material = run(r);
      o.ok = true;
    } catch (const std::exception& e) {
      o.error = e.what();
      ++failed;
    }
    outcomes.push_back(std::move(o));
    progress.update(outcomes.size(), mine);
  }
  progress.finish();
  // What every row was fitted with: shards merge only when this agrees.
  const nlohmann::json run = {
      {"manifest_fnv1a", file_hash(a.batch)},
      {"options",
       {{"model", a.model}, {"g", a.g}, {"quality", a.quality}, {"loss", a.loss},
        {"ior", a.ior_option && a.ior_option->count() > 0 ? nlohmann::json(a.ior) : nlohmann::json()},
        {"fit_ior", a.fit_ior}, {"relative", a.relative}, {"thickness_mm", a.thickness_mm},
        {"fit_thickness", a.fit_thickness}, {"beam_sigma_mm", a.beam_sigma_mm},
        {"beam_image", a.beam_image}, {"table", a.table}, {"oblique_table", a.oblique_table},
        {"table_photons", a.table_photons}, {"slab_photons", a.slab_photons},
        {"oblique_photons", a.oblique_photons}, {"allow_unconverged", a.allow_unconverged},
        {"exclude_radius_mm", a.exclude_option && a.exclude_option->count() > 0
                                  ? nlohmann::json(a.exclude_radius_mm)
                                  : nlohmann::json()}}}};
  const nlohmann::json summary =
      batch_summary(a.batch, rows.size(), outcomes,
                    shards > 1 ? std::to_string(shard) + "/" + std::to_string(shards) : "", run);
  check_finite_json(summary, a.output);
  write_file_atomically(a.output, summary.dump(2) + "\n");
  std::cout << "fitted " << outcomes.size() - std::size_t(failed) << " of " << outcomes.size()
            << " rows"
            << (shards > 1 ? " (shard " + a.shard + " of " + std::to_string(rows.size()) + ")"
                           : std::string())
            << "; summary " << a.output << '\n';
  // The rows that were fitted and the summary are kept (a job array reruns the failed rows from
  // it); the exit status still says that some failed.
  commit_pending_outputs();
  if (failed > 0)
    throw Error("--batch: " + std::to_string(failed) + " of " + std::to_string(outcomes.size()) +
                " rows failed (their errors are in " + a.output + ")");
}

}  // namespace

void register_fit_command(CLI::App& app) {
  auto args = std::make_shared<FitArguments>();
  CLI::App* cmd =
      app.add_subcommand("fit",
                         "Fit optical coefficients to measured profiles (lucent-profile JSON from "
                         "lucent acquire, or lucent's radial CSV from lucent profile / simulate "
                         "--exitance-csv) and write a material file. By default the model exact "
                         "to transport (tabulated) for radial normal-incidence data, with which "
                         "cheaper model would do. Several profiles of one material are fitted "
                         "jointly.");
  cmd->add_option("inputs", args->inputs, "profile files (.json or .csv)");
  cmd->add_option("-o,--output", args->output, "material file to write (.json)")->required();
  cmd->add_option("--model", args->model,
                  "auto (the accurate model, and which cheaper one is adequate), tabulated, dipole "
                  "or ddipole")
      ->capture_default_str();
  cmd->add_option("--g", args->g,
                  "Henyey-Greenstein g the tabulated model assumes (radial data cannot tell g "
                  "from sigma_s; the report says how far the answer moves)")
      ->check(number_in(0, 0.99, "(Henyey-Greenstein g)"))
      ->capture_default_str();
  cmd->add_option("--table", args->table,
                  "transport table for the tabulated model (default: the shipped one)");
  cmd->add_option(
      "--oblique-table", args->oblique_table,
      "oblique transport table (lucent tabulate --incidence-deg) for 2D captures at "
      "oblique incidence (default: the shipped one when it holds the capture's eta, "
      "g and incidence, else one built now and kept in ~/.cache/lucent; none: the directional "
      "dipole corrected by the radial table, fast and approximate)");
  cmd->add_option("--oblique-photons", args->oblique_photons,
                  "photons of an oblique table built for this fit (about 50 s per million on "
                  "2 cores)")
      ->check(CLI::Range(std::uint64_t(10'000), std::uint64_t(1'000'000'000)))
      ->capture_default_str();
  cmd->add_option("--thickness-mm", args->thickness_mm,
                  "the sample is a slab this thick, mm, for every input (default: what each "
                  "input says, thickness_mm and side, else semi-infinite); its tables are built "
                  "on first use and kept in ~/.cache/lucent")
      ->check(number_in(1e-3, 1e4, "mm"));
  cmd->add_flag("--allow-outside", args->allow_outside,
                "--batch: let rows write outside the manifest's folder (a job array writing to a "
                "scratch tree); without it such a row is refused before anything is fitted, so "
                "that a manifest from elsewhere cannot replace files of yours");
  cmd->add_flag("--fit-thickness", args->fit_thickness,
                "the sample is a slab of unknown thickness: fit it (one for every input) and say "
                "how well the data pin it, or that they cannot (named undetermined); uses the "
                "slab tables as --thickness-mm does");
  cmd->add_option("--beam-image", args->beam_image,
                  "the beam as an image of its spot on a flat white target through the same lens "
                  "(OpenEXR, linear, dark frame taken off; or PNG/TIFF codes taken as linear), for "
                  "captures without a white reference: every input's model is convolved with its "
                  "radial profile (over the inputs' own response)");
  cmd->add_option("--beam-pixel-mm", args->beam_pixel_mm,
                  "the beam image's pixel pitch on the target, mm (default: the first input's)")
      ->check(number_in(1e-4, 100, "mm"));
  cmd->add_option("--beam-sigma-mm", args->beam_sigma_mm,
                  "the beam (with the lens) as a round Gaussian of this sigma, mm, for every "
                  "input (default: each input's system response measured by its white reference, "
                  "where wider than the pixels; else a pencil beam)")
      ->check(number_in(1e-3, 100, "mm"));
  cmd->add_option("--slab-photons", args->slab_photons,
                  "photons per slab table built for --thickness-mm (9 thickness nodes per side)")
      ->check(CLI::Range(std::uint64_t(10'000), std::uint64_t(1'000'000'000)))
      ->capture_default_str();
  cmd->add_option("--table-photons", args->table_photons,
                  "photons per albedo node of a radial table built for this fit when the shipped "
                  "one lacks its --g (g > 0.9; about a minute per million on 2 cores, kept in "
                  "~/.cache/lucent)")
      ->check(CLI::Range(std::uint64_t(10'000), std::uint64_t(1'000'000'000)))
      ->capture_default_str();
  args->exclude_option = cmd->add_option("--exclude-radius-mm", args->exclude_radius_mm,
                                         "leave out samples closer to the entry point than this, "
                                         "mm, in every channel (default: "
                                         "per channel; tabulated: two pixels or 0.1 mean free "
                                         "path, dipoles: one transport mean "
                                         "free path)")
                             ->check(number_in(0, 1e6, "mm"));
  args->ior_option =
      cmd->add_option("--ior", args->ior,
                      "relative index of refraction of the sample (required with CSV)")
          ->check(number_in(0, 4, "(relative index of refraction)", true));
  cmd->add_flag("--fit-ior", args->fit_ior, "fit the index too (one for all channels)");
  cmd->add_flag("--relative", args->relative,
                "fit a global scale (automatic when the profile says it is relative)");
  cmd->add_option("--loss", args->loss, "none, huber:S or cauchy:S (S in standard errors)")
      ->capture_default_str();
  cmd->add_option(
         "--quality", args->quality,
         "fast, balanced or accurate: footprint quadrature order, samples used, tolerances")
      ->capture_default_str();
  cmd->add_option("--plot", args->plot,
                  "write the fit plot: profile, residuals and, for 2D samples, residual maps "
                  "(.svg, .pdf or .png, by the extension)");
  cmd->add_flag("--plot-log-r", args->plot_log_r, "the fit plot's r axis logarithmic");
  cmd->add_option("--report", args->report, "write everything per channel (JSON)");
  cmd->add_option("--name", args->name, "material name (default: the output file's stem)");
  cmd->add_flag("--allow-unconverged", args->allow_unconverged,
                "write the best values even when the solver did not converge");
  cmd->add_flag("--json", args->json, "print the report as JSON on stdout");
  cmd->add_flag("-q,--quiet", args->no_progress, "no progress line on standard error");
  cmd->add_option("--batch", args->batch,
                  "fit every row of this manifest (CSV: input, output, and optionally ior, model, "
                  "g, name per row; paths from the manifest's folder); -o is then the summary "
                  "(.json)");
  cmd->add_option("--shard", args->shard,
                  "with --batch: only rows i with i mod N = I (0-based I/N: a job array's task); "
                  "lucent merge joins the shards' summaries");
  cmd->callback([args] {
    if (!args->batch.empty()) return run_batch(*args);
    if (!args->shard.empty()) throw Error("--shard: only with --batch");
    if (args->inputs.empty()) throw Error("inputs: at least one profile file is required");
    run(*args);
  });
}

}  // namespace lucent::cli
