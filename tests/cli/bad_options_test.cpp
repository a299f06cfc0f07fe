// Bad-input table for the command-line options of every command (numbers with units, counts,
// seeds, threads, enumerations, compound values, output paths), and the all-or-nothing outputs:
// several files per command, existing folders, signals, temporaries of killed runs.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "bad_input.h"

namespace lucent::testing {
namespace {

std::vector<BadCase> option_cases() {
  const std::string sim = "simulate --material marble --photons 1000 --size 16 -o {dir}/s ";
  const std::string ren =
      "render --material marble --mesh sphere --technique reference "
      "--size 8x8 --reference-samples-pixel 1 -o {dir}/r.exr ";
  const std::string fit = "fit {world}/acq/profile.json -o {dir}/m.json ";
  const std::string acq = "acquire {world}/cap/capture.json -o {dir}/a ";
  const std::string pro = "profile --material marble -o {dir}/p.csv ";
  const std::string tab = "tabulate -o {dir}/t.lut --photons 1000 ";
  return {
      // simulate: the camera and the transport
      {"sim_full_well_zero", nullptr, sim + "--full-well-e 0", "--full-well-e"},
      {"sim_camera_scale_nan", nullptr, sim + "--camera-scale nan", "--camera-scale"},
      {"sim_read_noise_negative", nullptr, sim + "--read-noise-e -5", "--read-noise-e"},
      {"sim_black_level_huge", nullptr, sim + "--black-level-e 1e9", "--black-level-e"},
      {"sim_black_level_over_well", nullptr, sim + "--black-level-e 30000", "--black-level-e"},
      {"sim_seed_negative", nullptr, sim + "--seed -1", "--seed"},
      {"sim_seed_fraction", nullptr, sim + "--seed 1.5", "--seed"},
      {"sim_seed_too_big", nullptr, sim + "--seed 18446744073709551616", "--seed"},
      {"sim_photons_one", nullptr, sim + "--photons 1", "--photons"},
      {"sim_photons_fraction_exponent", nullptr, sim + "--photons 1e3.5", "--photons"},
      {"sim_photons_fraction_left", nullptr, sim + "--photons 1.05e1", "--photons"},
      {"sim_photons_negative_exponent", nullptr, sim + "--photons 1e-3", "--photons"},
      {"sim_seed_exponent_overflow", nullptr, sim + "--seed 1e40", "--seed"},
      {"sim_threads_huge", nullptr, sim + "--threads 100000", "--threads"},
      {"sim_threads_negative", nullptr, sim + "--threads -1", "--threads"},
      {"sim_size_zero", nullptr, sim + "--size 0", "--size"},
      {"sim_pixel_nan", nullptr, sim + "--pixel-mm nan", "--pixel-mm"},
      {"sim_max_radius_overflow", nullptr, sim + "--max-radius-mm 1e400", "--max-radius-mm"},
      {"sim_bits_12", nullptr, sim + "--bits 12", "--bits"},
      {"sim_exposure_zero", nullptr, sim + "--exposures 1/0", "--exposures"},
      {"sim_exposures_decreasing", nullptr, sim + "--exposures 1/10,1/100", "--exposures"},
      {"sim_response_foo", nullptr, sim + "--response foo", "--response"},
      {"sim_source_foo", nullptr, sim + "--source foo", "--source"},
      {"sim_incidence_95", nullptr, sim + "--incidence-deg 95", "incidence"},
      {"sim_material_missing", nullptr, "simulate --material {dir}/none.json -o {dir}/s",
       "none.json"},
      {"sim_exitance_csv_folder_missing", nullptr, sim + "--exitance-csv {dir}/nodir/x.csv",
       "nodir"},
      {"sim_output_exists",
       [](const fs::path& d) {
         fs::create_directories(d / "s");
         write_file(d / "s/bracket_9.png", "an earlier capture's");
       },
       sim, "--force"},
      // render / view scene options
      {"render_threads_negative", nullptr, ren + "--reference-threads -1", "--reference-threads"},
      {"render_seed_word", nullptr, ren + "--seed abc", "--seed"},
      {"render_view_far", nullptr, ren + "--view 0,0,1e20", "--view"},
      {"render_view_two_numbers", nullptr, ren + "--view 0,0", "--view"},
      {"render_fur_coverage_foo", nullptr, ren + "--fur-coverage foo", "--fur-coverage"},
      // A coat 96 000 texels tall (1.5 mm over a 0.001 mm tile of 64 texels): hours of marching.
      {"render_fur_coat_too_tall", nullptr, ren + "--fur-coat on --fur-tile-mm 0.001",
       "--fur-height-mm"},
      {"render_size_zero", nullptr, ren.substr(0, ren.find("--size")) + "--size 0x0 -o {dir}/r.exr",
       "--size"},
      {"render_object_size_huge", nullptr, ren + "--object-size-mm 1e308", "--object-size-mm"},
      {"render_light_kind", nullptr, ren + "--light spot:0,1,0:1,1,1", "--light"},
      {"render_light_1e38", nullptr, ren + "--light directional:0,1,0:1e38,1,1", "--light"},
      {"render_light_far", nullptr, ren + "--light point:1e30,0,0:1,1,1", "--light"},
      {"render_light_zero_direction", nullptr, ren + "--light directional:0,0,0:1,1,1", "--light"},
      {"render_backdrop_negative", nullptr, ren + "--backdrop -1,0,0", "--backdrop"},
      {"render_exposure_zero", nullptr, ren + "--exposure 0", "--exposure"},
      {"render_roughness_two", nullptr, ren + "--roughness 2", "--roughness"},
      {"render_technique_foo", nullptr, ren + "--technique foo", "--technique"},
      {"render_model_foo", nullptr, ren + "--model foo", "--model"},
      {"render_sampling_foo", nullptr, ren + "--reference-sampling foo", "--reference-sampling"},
      {"render_samples_zero", nullptr, ren + "--reference-samples-pixel 0",
       "--reference-samples-pixel"},
      {"render_passes_zero", nullptr, ren + "--reference-passes 0", "--reference-passes"},
      {"render_single_scattering_foo", nullptr, ren + "--single-scattering foo",
       "--single-scattering"},
      {"render_angular_foo", nullptr, ren + "--angular foo", "--angular"},
      {"render_geometry_factor_foo", nullptr, ren + "--geometry-factor foo", "--geometry-factor"},
      {"bench_truth_foo", nullptr, "bench tradeoff --truth foo --sweep tiny --out-dir {dir}",
       "--truth"},
      {"bench_scene_size_zero", nullptr,
       "bench tradeoff --scenes sphere/marble/point/0 --sweep tiny --out-dir {dir}", "--scenes"},
      {"render_single_scattering_sh", nullptr,
       ren.substr(0, ren.find("--technique")) + "--technique sh --single-scattering on " +
           ren.substr(ren.find("--technique") + 22),
       "--single-scattering"},
      {"render_pathtrace_samples_zero", nullptr, ren + "--pathtrace-samples-pixel 0",
       "--pathtrace-samples-pixel"},
      {"render_pathtrace_passes_zero", nullptr, ren + "--pathtrace-passes 0", "--pathtrace-passes"},
      {"render_pathtrace_jitter_foo", nullptr, ren + "--pathtrace-jitter foo",
       "--pathtrace-jitter"},
      {"render_stats_folder_missing", nullptr, ren + "--stats {dir}/nodir/s.json", "nodir"},
      {"render_output_folder_missing", nullptr,
       ren.substr(0, ren.find("-o ")) + "-o {dir}/nodir/r.exr", "nodir"},
      // fit
      {"fit_exclude_nan", nullptr, fit + "--exclude-radius-mm nan", "--exclude-radius-mm"},
      {"fit_exclude_negative", nullptr, fit + "--exclude-radius-mm -1", "--exclude-radius-mm"},
      {"fit_ior_zero", nullptr, fit + "--ior 0", "--ior"},
      {"fit_oblique_photons_few", nullptr, fit + "--oblique-photons 10", "--oblique-photons"},
      {"fit_shard_without_batch", nullptr, fit + "--shard 0/2", "--shard"},
      {"fit_batch_shard_out_of_range", nullptr,
       "fit --batch {world}/acq/profile.json --shard 2/2 -o {dir}/s.json", "--shard"},
      {"fit_batch_not_a_manifest", nullptr, "fit --batch {world}/acq/profile.json -o {dir}/s.json",
       "column"},
      {"fit_ior_five", nullptr, fit + "--ior 5", "--ior"},
      {"fit_g_0995", nullptr, fit + "--g 0.995", "--g"},
      {"fit_loss_trailing_garbage", nullptr, fit + "--loss huber:1abc", "--loss"},
      {"fit_loss_foo", nullptr, fit + "--loss foo", "--loss"},
      {"fit_quality_foo", nullptr, fit + "--quality foo", "--quality"},
      {"fit_model_foo", nullptr, fit + "--model foo", "--model"},
      {"fit_table_missing", nullptr, fit + "--table {dir}/none.lut", "none.lut"},
      {"fit_plot_folder_missing", nullptr, fit + "--plot {dir}/nodir/f.png", "nodir"},
      {"fit_output_is_folder", nullptr, "fit {world}/acq/profile.json -o {dir}", "-o"},
      {"fit_output_empty", nullptr, "fit {world}/acq/profile.json -o ''", "-o"},
      {"fit_plot_not_png", nullptr, fit + "--plot {dir}/f.json", "--plot"},
      {"fit_plot_txt", nullptr, fit + "--plot {dir}/fit.txt", ".svg, .pdf or .png"},
      // a warning of the work (dragon:4's non-manifold edges) does not join the error line
      {"render_dragon_bad_env", nullptr,
       "render --material marble --mesh dragon:4 --technique reference --size 8x8 "
       "--reference-samples-pixel 1 --env {dir}/none.exr -o {dir}/r.exr",
       "none.exr"},
      // acquire
      {"acquire_bins_zero", nullptr, acq + "--bins 0", "--bins"},
      {"acquire_bins_negative", nullptr, acq + "--bins -3", "--bins"},
      {"acquire_radius_overflow", nullptr, acq + "--radius-mm 1e400", "--radius-mm"},
      {"acquire_radius_max_double", nullptr, acq + "--radius-mm 1.7976931348623157e308",
       "(0, 1e+06] mm"},
      {"acquire_min_pixels_one", nullptr, acq + "--min-pixels 1", "--min-pixels"},
      // profile
      {"profile_r_huge", nullptr, pro + "--r 1e308", "--r"},
      {"profile_r_negative", nullptr, pro + "--r -1", "--r"},
      {"profile_range_backwards", nullptr, pro + "--r-range 5:1:10", "--r-range"},
      {"profile_quantity_foo", nullptr, pro + "--r 1 --quantity foo", "--quantity"},
      {"profile_model_foo", nullptr, pro + "--r 1 --model foo", "--model"},
      // tabulate, compare
      {"tabulate_seed_negative", nullptr, tab + "--seed -1", "--seed"},
      {"tabulate_threads_huge", nullptr, tab + "--threads 5000", "--threads"},
      {"compare_scale_word", nullptr, "compare {world}/env.exr {world}/env.exr --scale x",
       "--scale"},
      // long jobs refuse before they start
      {"bench_render_folder_missing", nullptr, "bench render --out {dir}/nodir/r.csv", "nodir"},
      {"bench_fit_folder_missing", nullptr, "bench fit --out-dir {dir}/nodir", "nodir"},
      {"render_frames_huge", nullptr,
       "render --material marble --size 8x8 -o {dir}/r.exr --maps-frames 1000000000",
       "--maps-frames"},
      {"render_disc_points_huge", nullptr,
       "render --material marble --size 8x8 -o {dir}/r.exr --maps-disc-points 100000000",
       "--maps-disc-points"},
      {"tabulate_eta_low", nullptr, tab + "--eta 0.5", "--eta"},
      {"tabulate_incidence_89", nullptr, tab + "--incidence-deg 89", "--incidence-deg"},
      {"tabulate_incidence_decreasing", nullptr, tab + "--incidence-deg 40,30", "--incidence-deg"},
      {"tabulate_phi_bins_zero", nullptr, tab + "--phi-bins 0", "--phi-bins"},
      {"tabulate_white_photons_over", nullptr, tab + "--white-photons 5000", "--white-photons"},
      {"tabulate_g_099_5", nullptr, tab + "--g 0.995", "--g"},
      // export
      {"export_to_blender", nullptr, "export --material marble --to blender -o {dir}/m.blend",
       "--to"},
      {"export_unit_inch", nullptr,
       "export --material marble --to pbrt --scene-unit inch -o {dir}/m.pbrt", "--scene-unit"},
      {"export_gltf_in_cm", nullptr,
       "export --material marble --to gltf --scene-unit cm -o {dir}/m.gltf", "--scene-unit"},
      {"export_wrong_extension", nullptr, "export --material marble --to mitsuba -o {dir}/m.pbrt",
       "-o"},
      {"export_unknown_material", nullptr, "export --material marbel --to pbrt -o {dir}/m.pbrt",
       "marbel"},
      {"tabulate_merge_garbage", bytes_file("bad.lut", "garbage\n"),
       "tabulate -o {dir}/t.lut --merge {dir}/bad.lut", "bad.lut"},
      {"fit_table_garbage", bytes_file("bad.lut", "garbage\n"), fit + "--table {dir}/bad.lut",
       "bad.lut"},
      {"fit_table_truncated",
       [](const fs::path& d) {
         const std::string t = read_bytes(fs::path(LUCENT_SOURCE_DIR) / "materials/tables/transport.lut");
         write_file(d / "t.lut", t.substr(0, 5000));
       },
       fit + "--table {dir}/t.lut", "t.lut"},
      {"profile_range_count_zero", nullptr, pro + "--r-range 0:1:0", "--r-range"},
      {"profile_range_spacing", nullptr, pro + "--r-range 0:1:10:cubic", "--r-range"},
      {"sim_thickness_negative", nullptr, sim + "--thickness-mm -1", "thickness"},
      {"sim_both_sides_without_thickness", nullptr, sim + "--side both", "--thickness-mm"},
      {"sim_side_misspelt", nullptr, sim + "--thickness-mm 2 --side bothe", "--side"},
      {"acquire_profile_as_capture", nullptr, "acquire {world}/acq/profile.json -o {dir}/a",
       "profile.json"},
      // the command line itself
      {"unknown_option", nullptr, "fit {world}/acq/profile.json -o {dir}/m.json --colour red",
       "--colour"},
      {"no_subcommand", nullptr, "", "subcommand"},
  };
}

class BadOptions : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadOptions, AreRefusedCleanly) { expect_clean_refusal(GetParam()); }

INSTANTIATE_TEST_SUITE_P(Table, BadOptions, ::testing::ValuesIn(option_cases()),
                         [](const auto& info) { return info.param.name; });

// ---- all or nothing -----------------------------------------------------------------------------

std::string quoted(const fs::path& p) { return "\"" + p.string() + "\""; }

TEST(Outputs, AnExistingFolderIsReplacedWholeOnlyWithForce) {
  const fs::path dir = scratch_dir("force");
  const std::string sim = "simulate --material marble --photons 1000 --size 16 --quiet -o " +
                          quoted(dir / "s");
  ASSERT_EQ(run_lucent(sim).exit_code, 0);
  ASSERT_TRUE(fs::exists(dir / "s/white_0.png"));
  // The second capture has no white reference: with --force nothing of the first may remain.
  const CommandResult r = run_lucent(sim + " --no-white-reference --force");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(fs::exists(dir / "s/white_0.png"));
  EXPECT_TRUE(fs::exists(dir / "s/capture.json"));
  for (const auto& e : fs::directory_iterator(dir)) {
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
  }
  fs::remove_all(dir);
}

// A whole number may be typed with an exponent (--photons 1e5 read as arbitrary when refused).
TEST(Outputs, WholeNumbersTakeAnExponent) {
  const fs::path dir = scratch_dir("exponent");
  const CommandResult r = run_lucent(
      "simulate --material marble --photons 2.5e3 --size 16 --quiet -o " + quoted(dir / "s"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto truth = nlohmann::json::parse(read_bytes(dir / "s/truth.json"));
  EXPECT_EQ(truth["transport"]["photons_per_channel"], 2500);
  fs::remove_all(dir);
}

TEST(Outputs, TheSeedDrivesTheCameraNoiseAndIsRecorded) {
  const fs::path dir = scratch_dir("seeds");
  for (const char* seed : {"1", "2"}) {
    ASSERT_EQ(run_lucent("simulate --material marble --photons 1000 --size 16 --quiet --seed " +
                         std::string(seed) + " -o " + quoted(dir / seed))
                  .exit_code,
              0);
  }
  const auto truth = nlohmann::json::parse(read_bytes(dir / "2/truth.json"));
  EXPECT_EQ(truth["transport"]["seed"], 2);
  EXPECT_EQ(truth["camera"]["seed"], 2);
  // A dipole source has no transport noise: the brackets differ only by the camera's.
  const std::string dipole = "simulate --material marble --source dipole --size 16 --quiet ";
  ASSERT_EQ(run_lucent(dipole + "--seed 1 -o " + quoted(dir / "d1")).exit_code, 0);
  ASSERT_EQ(run_lucent(dipole + "--seed 2 -o " + quoted(dir / "d2")).exit_code, 0);
  ASSERT_EQ(run_lucent(dipole + "--seed 2 -o " + quoted(dir / "d2b")).exit_code, 0);
  EXPECT_NE(read_bytes(dir / "d1/bracket_2.png"), read_bytes(dir / "d2/bracket_2.png"));
  EXPECT_EQ(read_bytes(dir / "d2/bracket_2.png"), read_bytes(dir / "d2b/bracket_2.png"));
  fs::remove_all(dir);
}

TEST(Outputs, EverySubcommandAnswersVersion) {
  for (const char* sub : {"profile", "simulate", "acquire", "fit", "bench", "render", "view",
                          "tabulate", "compare"}) {
    const CommandResult r = run_lucent(std::string(sub) + " --version");
    EXPECT_EQ(r.exit_code, 0) << sub << ": " << r.err;
    EXPECT_EQ(r.out.rfind("lucent ", 0), 0u) << sub << ": " << r.out;
  }
}

// Waits (up to 60 s) until lucent has a temporary in `dir`, i.e. is in the middle of its work.
bool wait_for_temporary(const fs::path& dir) {
  for (int i = 0; i < 600; ++i) {
    if (has_temporary(dir)) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return false;
}

TEST(Outputs, SigintAndSigtermLeaveNothingBehind) {
  for (const int sig : {SIGTERM, SIGINT}) {
    const fs::path dir = scratch_dir("signal-" + std::to_string(sig));
    const pid_t pid = spawn_lucent("simulate --material marble --photons 200000000 --threads 1 "
                                   "--quiet -o " + quoted(dir / "s"),
                                   dir.parent_path() / ("signal-log-" + std::to_string(sig)));
    ASSERT_TRUE(wait_for_temporary(dir)) << "no temporary folder appeared";
    ::kill(pid, sig);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << "status " << status;
    EXPECT_FALSE(has_temporary(dir));
    EXPECT_FALSE(fs::exists(dir / "s"));
    fs::remove_all(dir);
  }
}

TEST(Outputs, TemporariesOfAKilledRunAreRemovedByTheNextRun) {
  const fs::path dir = scratch_dir("sigkill");
  const pid_t pid = spawn_lucent("simulate --material marble --photons 200000000 --threads 1 "
                                 "--quiet -o " + quoted(dir / "s"),
                                 dir.parent_path() / "sigkill-log");
  ASSERT_TRUE(wait_for_temporary(dir));
  ::kill(pid, SIGKILL);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(has_temporary(dir));  // nothing can clean up after SIGKILL ...
  const CommandResult r =
      run_lucent("profile --material marble --r 1 -o " + quoted(dir / "p.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(has_temporary(dir));  // ... but the next run writing here does
  EXPECT_TRUE(fs::exists(dir / "p.csv"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace lucent::testing
