// `lucent simulate`: Monte Carlo capture of a material on the virtual rig.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <memory>
#include <sstream>

#include "commands.h"
#include "lucent/acquire/simulate.h"
#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "progress.h"
#include "validators.h"

namespace lucent::cli {
namespace {

struct SimulateArguments {
  std::string material;
  std::string output;
  std::string exposures = "1/1000,1/250,1/60,1/15,1/4";
  std::string response;  // empty: srgb for PNG brackets, linear for DNG
  std::string bracket_format = "png";
  std::string source = "montecarlo";
  std::string exitance_csv;
  std::string side = "reflected";
  bool no_white = false;
  bool no_dark = false;
  bool no_noise = false;
  bool json = false;
  bool quiet = false;
  bool force = false;
  bool size_given = false;   // --size on the command line
  bool pixel_given = false;  // --pixel-mm on the command line
  acquire::SimulateOptions options;
};

// "1/1000,1/250,0.5" -> seconds.
std::vector<double> parse_exposures(const std::string& text) {
  std::vector<double> times;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const auto slash = item.find('/');
    double value = 0;
    try {
      std::size_t used = 0;
      if (slash == std::string::npos) {
        value = std::stod(item, &used);
        if (used != item.size()) throw std::invalid_argument(item);
      } else {
        const std::string num = item.substr(0, slash), den = item.substr(slash + 1);
        std::size_t u1 = 0, u2 = 0;
        value = std::stod(num, &u1) / std::stod(den, &u2);
        if (u1 != num.size() || u2 != den.size()) throw std::invalid_argument(item);
      }
    } catch (const std::exception&) {
      throw Error("--exposures: expected times in s like 1/1000,1/250,0.5, got '" + item + "'");
    }
    // The range acquire reads (a shorter one was written and then refused).
    if (!(value >= 1e-9 && value <= 1e6)) {
      throw Error("--exposures: each exposure must be a time in [1e-9, 1e6] s, got '" + item + "'");
    }
    times.push_back(value);
  }
  if (times.empty()) throw Error("--exposures: expected at least one exposure time");
  return times;
}

void run(SimulateArguments& args) {
  acquire::SimulateOptions& o = args.options;
  o.material = materials::load_material(args.material);
  const acquire::SimulationField field = acquire::default_simulation_field(
      o.material, o.transport.size, o.transport.pixel_mm, args.size_given, args.pixel_given);
  o.transport.size = field.size;
  o.transport.pixel_mm = field.pixel_mm;
  if (args.bracket_format == "png")
    o.bracket_format = acquire::BracketFormat::kPng;
  else if (args.bracket_format == "dng")
    o.bracket_format = acquire::BracketFormat::kDng;
  else
    throw Error("--bracket-format: expected 'png' or 'dng', got '" + args.bracket_format + "'");
  if (args.response.empty()) args.response = args.bracket_format == "dng" ? "linear" : "srgb";
  if (args.response == "srgb")
    o.camera.response = acquire::Response::kSrgb;
  else if (args.response == "linear")
    o.camera.response = acquire::Response::kLinear;
  else
    throw Error("--response: expected 'srgb' or 'linear', got '" + args.response + "'");
  o.camera.exposures_s = parse_exposures(args.exposures);
  if (args.source == "montecarlo")
    o.source = acquire::RadianceSource::kMonteCarlo;
  else if (args.source == "dipole")
    o.source = acquire::RadianceSource::kDipole;
  else if (args.source == "ddipole")
    o.source = acquire::RadianceSource::kDirectionalDipole;
  else
    throw Error("--source: expected montecarlo, dipole or ddipole, got '" + args.source + "'");
  if (args.side != "reflected" && args.side != "transmitted" && args.side != "both")
    throw Error("--side: expected reflected (the lit side), transmitted (the far side) or both, "
                "got '" + args.side + "'");
  o.transport.far_side = args.side == "transmitted";
  if (args.side != "reflected" && !std::isfinite(o.transport.thickness_mm))
    throw Error("--side " + args.side + ": the far side needs --thickness-mm");
  o.camera.noise = !args.no_noise;
  o.white_reference = !args.no_white;
  o.dark_frame = !args.no_dark;
  if (!args.exitance_csv.empty()) {
    check_output_file(args.exitance_csv, ".csv", "--exitance-csv");  // before the simulation
    o.exitance_csv = args.exitance_csv;
  }

  ProgressLine line("simulate", "photons", args.quiet || args.json);
  const auto progress = [&](std::uint64_t done, std::uint64_t total) { line.update(done, total); };
  // Both sides: one capture folder each, OUTDIR/reflected and OUTDIR/transmitted, from the same
  // photons (the same seed: the far side's run repeats the lit side's paths and scores the other
  // surface), committed together.
  std::vector<std::pair<std::string, acquire::SimulateSummary>> sides;
  if (args.side == "both") {
    AtomicOutputDir both(args.output);
    const std::optional<std::string> csv = o.exitance_csv;
    for (const bool far : {false, true}) {
      o.transport.far_side = far;
      const char* name = far ? "transmitted" : "reflected";
      // Each side's radial table in its own file: FILE-reflected.csv, FILE-transmitted.csv.
      if (csv) {
        const std::filesystem::path p(*csv);
        o.exitance_csv = (p.parent_path() / (p.stem().string() + "-" + name + p.extension().string())).string();
      }
      sides.emplace_back(args.output + "/" + name,
                         acquire::run_simulation(o, both.temporary() / name, progress));
    }
    both.commit();
  } else {
    sides.emplace_back(args.output, acquire::run_simulation(o, args.output, progress));
  }
  line.finish();
  // Said once the options have passed (a refusal stays one line).
  if (!field.why.empty() && !args.quiet && !args.json) std::cerr << field.why << '\n';

  nlohmann::json all = nlohmann::json::array();
  for (const auto& [folder, summary] : sides) {
    const auto& t = summary.transport;
    if (args.json) {
      nlohmann::json j = {{"output", folder},
                          {"side", t.options.far_side ? "transmitted" : "reflected"},
                          {"files", summary.files},
                          {"wall_seconds", t.wall_seconds},
                          {"threads", t.threads_used},
                          {"camera_scale", summary.camera_scale}};
      for (int c = 0; c < 3; ++c) {
        j["diffuse_reflectance"].push_back(t.channels[c].diffuse_reflectance.value);
        j["photons"].push_back(t.channels[c].photons);
      }
      all.push_back(j);
    } else if (!args.quiet) {
      std::cout << "simulated " << o.material.name << ": " << t.channels[0].photons
                << " photons per channel in " << t.wall_seconds << " s on " << t.threads_used
                << " threads\n";
      const char* names = "RGB";
      for (int c = 0; c < 3; ++c) {
        const auto& ch = t.channels[c];
        std::cout << "  " << names[c] << ": diffuse reflectance " << ch.diffuse_reflectance.value
                  << " +- " << ch.diffuse_reflectance.standard_error << ", specular "
                  << ch.specular_reflectance.value << ", transmitted " << ch.transmittance.value
                  << ", absorbed " << ch.absorbed.value << '\n';
      }
      std::cout << "wrote " << summary.files.size() << " files to " << folder << '\n';
    }
  }
  // One side: the object as before; both: an array of the two.
  if (args.json) std::cout << (all.size() == 1 ? all[0] : all).dump(2) << '\n';
}

// Options of `lucent simulate`, added in the help's order, one group per concern.

// What is simulated and where it goes: the material, the output folder and the radiance source.
void add_subject_options(CLI::App* cmd, SimulateArguments& args) {
  cmd->add_option("--material", args.material, "bundled material name or material file")
      ->required();
  cmd->add_option("-o,--output", args.output,
                  "output folder (created whole; an existing one is refused unless --force)")
      ->required();
  cmd->add_flag("--force", args.force,
                "replace an existing output folder whole (its other files are removed)");
  cmd->add_option("--source", args.source,
                  "exit radiance from montecarlo (photon transport), or from the dipole / ddipole "
                  "model (for round trips of lucent fit)")
      ->capture_default_str();
}

// Photon transport: photons, seed, threads, the slab and the beam's width.
void add_transport_options(CLI::App* cmd, acquire::SimulateOptions& o) {
  cmd->add_option("--photons", o.transport.photons, "photons per colour channel")
      ->transform(whole_in(100, 1000000000000000ull, "photons per channel"))
      ->capture_default_str();
  cmd->add_option("--seed", o.transport.seed, "random seed (results identical for any --threads)")
      ->transform(seed_value())
      ->capture_default_str();
  cmd->add_option("--threads", o.transport.threads, "worker threads (0 = all cores)")
      ->transform(thread_count())
      ->capture_default_str();
  cmd->add_option("--thickness-mm", o.transport.thickness_mm,
                  "slab thickness in mm (default: semi-infinite)");
  cmd->add_option("--beam-sigma-mm", o.transport.beam_sigma_mm,
                  "a beam of finite width: Gaussian footprint of this sigma, mm (0: a pencil "
                  "beam); the white reference is lit by the same beam")
      ->check(number_in(0, 100, "mm"))
      ->capture_default_str();
}

// The lens: its blur and veiling glare.
void add_lens_options(CLI::App* cmd, acquire::SimulateOptions& o) {
  cmd->add_option("--lens-blur-mm", o.lens_blur_mm,
                  "lens blur: Gaussian sigma on the sample, mm (sample and white reference)")
      ->check(number_in(0, 100, "mm"))
      ->capture_default_str();
  cmd->add_option("--glare", o.glare,
                  "veiling glare: the fraction of each pixel's light the lens spreads over the "
                  "field (a clean lens has 0.01-0.05)")
      ->check(number_in(0, 0.99, "a fraction"))
      ->capture_default_str();
  cmd->add_option("--glare-radius-mm", o.glare_radius_mm,
                  "core radius a of the glare kernel a / (2 pi (r^2 + a^2)^1.5), mm")
      ->check(number_in(1e-3, 1000, "mm"))
      ->capture_default_str();
}

// The rig's geometry: the side seen, the beam's and the camera's angles.
void add_geometry_options(CLI::App* cmd, SimulateArguments& args) {
  acquire::SimulateOptions& o = args.options;
  cmd->add_option("--side", args.side,
                  "which side the camera sees: reflected (the lit side), transmitted (a slab's "
                  "far side, the camera below; needs --thickness-mm) or both (OUTDIR/reflected "
                  "and OUTDIR/transmitted, one capture each, the same photons)")
      ->capture_default_str();
  cmd->add_option("--incidence-deg", o.transport.incidence_deg,
                  "beam angle from the normal, degrees [0, 90)")
      ->capture_default_str();
  cmd->add_option("--azimuth-deg", o.transport.azimuth_deg,
                  "beam direction of travel in the image plane, degrees from +x")
      ->check(number_in(-360, 360, "degrees"))
      ->capture_default_str();
  cmd->add_option("--view-deg", o.transport.view_deg,
                  "camera angle from the normal, degrees [0, 90)")
      ->capture_default_str();
  cmd->add_option("--view-azimuth-deg", o.transport.view_azimuth_deg,
                  "camera azimuth, degrees from +x")
      ->check(number_in(-360, 360, "degrees"))
      ->capture_default_str();
}

// --size and --pixel-mm: whether each was given decides the default field.
struct FieldOptions {
  CLI::Option* size = nullptr;
  CLI::Option* pixel = nullptr;
};

// The field imaged: its size, pixel pitch and the radial table's extent.
FieldOptions add_field_options(CLI::App* cmd, acquire::SimulateOptions& o) {
  FieldOptions field;
  field.size = cmd->add_option("--size", o.transport.size,
                               "image width and height, pixels (default: the field holds 3.5 "
                               "diffusion lengths of the slowest channel each side of the beam, "
                               "at most 1024 pixels)")
                   ->transform(whole_in(1, 16384, "an image size in pixels"));
  field.pixel =
      cmd->add_option("--pixel-mm", o.transport.pixel_mm,
                      "pixel pitch on the sample, mm (default: a quarter of the shortest transport "
                      "mean free path, 0.02..0.1 mm, coarser when the field would pass 1024 "
                      "pixels)")
          ->check(number_in(0, 100, "mm", true));
  cmd->add_option("--max-radius-mm", o.transport.max_radius_mm,
                  "outer radius of the radial exitance table, mm")
      ->check(number_in(0, 1e6, "mm", true))
      ->capture_default_str();
  return field;
}

// The camera: exposures, encoding, sensor and the extra frames it takes.
void add_camera_options(CLI::App* cmd, SimulateArguments& args) {
  acquire::SimulateOptions& o = args.options;
  cmd->add_option("--exposures", args.exposures, "exposure times in s, increasing")
      ->capture_default_str();
  cmd->add_option("--response", args.response,
                  "camera encoding: srgb or linear (default: srgb for PNG, linear for DNG)");
  cmd->add_option("--bracket-format", args.bracket_format,
                  "bracket files: png (the camera's encoding) or dng (a Bayer sensor's linear "
                  "RAW codes with black level, exposure time and ISO in each file)")
      ->capture_default_str();
  cmd->add_option("--bits", o.camera.bits, "bits per channel: 8 or 16")
      ->transform(whole_in(8, 16, "bits per channel (8 or 16)"))
      ->capture_default_str();
  cmd->add_option("--full-well-e", o.camera.full_well_e, "electrons at saturation")
      ->check(number_in(100, 1e9, "electrons"))
      ->capture_default_str();
  cmd->add_option("--read-noise-e", o.camera.read_noise_e, "read noise, electrons rms")
      ->check(number_in(0, 1e8, "electrons rms"))
      ->capture_default_str();
  cmd->add_option("--black-level-e", o.camera.black_level_e, "pedestal, electrons")
      ->check(number_in(0, 5e8, "electrons"))
      ->capture_default_str();
  cmd->add_option("--camera-scale", o.camera.electrons_per_radiance_s,
                  "electrons per (radiance x s); 0 = brightest pixel half-fills the well at the "
                  "shortest exposure")
      ->check(number_in(0, 1e30, "electrons per (radiance s); 0: automatic"))
      ->capture_default_str();
  cmd->add_flag("--no-noise", args.no_noise, "noise-free camera (exact expected values)");
  cmd->add_flag("--no-white-reference", args.no_white, "do not image the white reference");
  cmd->add_flag("--no-dark", args.no_dark, "do not take a dark frame");
}

// What is written and said: transport only, the exitance CSV, JSON or quiet.
void add_report_options(CLI::App* cmd, SimulateArguments& args) {
  cmd->add_flag("--profile-only", args.options.profile_only,
                "transport only: no images, no capture.json");
  cmd->add_option("--exitance-csv", args.exitance_csv,
                  "also write the radial exitance R(r) (mm^-2 per unit power) and totals as CSV "
                  "(--side both: FILE-reflected.csv and FILE-transmitted.csv)");
  cmd->add_flag("--json", args.json, "print a JSON summary on stdout");
  cmd->add_flag("-q,--quiet", args.quiet, "no progress or summary");
}

}  // namespace

void register_simulate_command(CLI::App& app) {
  auto args = std::make_shared<SimulateArguments>();
  CLI::App* cmd = app.add_subcommand(
      "simulate",
      "Virtual capture rig: Monte Carlo photon transport in a slab (Henyey-Greenstein phase, "
      "Fresnel boundary) lit by a pencil beam of unit power, imaged by a camera model into "
      "exposure "
      "brackets with a white reference and a dark frame. Writes OUTDIR/capture.json for lucent "
      "acquire, the bracket PNGs, truth.json and truth_radiance.exr (mm^-2 sr^-1 per unit power).");
  add_subject_options(cmd, *args);
  add_transport_options(cmd, args->options);
  add_lens_options(cmd, args->options);
  add_geometry_options(cmd, *args);
  const FieldOptions field = add_field_options(cmd, args->options);
  add_camera_options(cmd, *args);
  add_report_options(cmd, *args);
  cmd->callback([args, size = field.size, pixel = field.pixel] {
    args->size_given = size->count() > 0;
    args->pixel_given = pixel->count() > 0;
    set_replace_folders(args->force);
    run(*args);
  });
}

}  // namespace lucent::cli
