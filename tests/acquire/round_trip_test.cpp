// simulate -> acquire: the calibrated profile recovers the simulated exit radiance within noise.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>

#include "lucent/acquire/acquire.h"
#include "lucent/acquire/simulate.h"
#include "lucent/imaging/image_io.h"

namespace lucent::acquire {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("lucent-rt-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

// The truth binned exactly as acquire bins the measurement: the sum of the truth (and of the
// squares of its standard error) over the pixels whose centres fall in bin b, and their number.
struct BinnedTruth {
  double sum = 0, se2 = 0;
  int n = 0;
};
BinnedTruth bin_truth(const Profile& profile, std::size_t b, int c, const imaging::ImageRgb& truth,
                      const imaging::ImageRgb* truth_se) {
  BinnedTruth t;
  const bool last = b + 1 == profile.radial.size();
  for (int j = 0; j < truth.height; ++j) {
    for (int i = 0; i < truth.width; ++i) {
      const double r =
          0.25 * std::hypot(i + 0.5 - profile.beam_point_px[0], j + 0.5 - profile.beam_point_px[1]);
      if (r >= profile.radial.r_inner_mm[b] &&
          (r < profile.radial.r_outer_mm[b] || (last && r <= profile.radial.r_outer_mm[b]))) {
        t.sum += truth.at(i, j, c);
        if (truth_se) t.se2 += double(truth_se->at(i, j, c)) * truth_se->at(i, j, c);
        ++t.n;
      }
    }
  }
  return t;
}

TEST(RoundTrip, SimulateThenAcquireRecoversTheRadianceInAbsoluteUnits) {
  const fs::path sim = fresh_dir("sim"), acq = fresh_dir("acq");
  SimulateOptions o;
  o.material = materials::load_material("potato");
  o.transport.photons = 60000;
  o.transport.size = 64;
  o.transport.pixel_mm = 0.25;
  o.transport.threads = 2;
  o.transport.seed = 11;  // drives the camera noise too
  run_simulation(o, sim);
  AcquireOptions ao;
  ao.bins = 40;
  const AcquireSummary summary = run_acquire(sim / "capture.json", acq, ao);
  ASSERT_TRUE(summary.calibrated);
  // The entry point sits on the corner of the four middle pixels: (32, 32) in pixel units.
  EXPECT_NEAR(summary.beam_point_px[0], 32.0, 0.1);
  EXPECT_NEAR(summary.beam_point_px[1], 32.0, 0.1);
  ASSERT_TRUE(summary.beam_power.has_value());  // from the white reference, in camera units

  // The truth binned exactly as acquire bins the measurement: pi times the mean radiance of the
  // pixels whose centres fall in each bin.
  const Profile profile = read_profile(acq / "profile.json");
  const imaging::ImageRgb truth = imaging::read_exr(sim / "truth_radiance.exr");
  int bins = 0, within = 0;
  for (std::size_t b = 0; b < profile.radial.size(); ++b) {
    for (int c = 0; c < 3; ++c) {
      const BinnedTruth t = bin_truth(profile, b, c, truth, nullptr);
      const double sum = t.sum;
      const int n = t.n;
      if (n != profile.radial.count[c][b])
        continue;  // a masked pixel changed the set: skip the bin
      const double expected = std::numbers::pi * sum / n;
      const double z =
          (profile.radial.value[c][b] - expected) / profile.radial.standard_error[c][b];
      ++bins;
      within += std::abs(z) < 4;
    }
  }
  EXPECT_GT(bins, 90);
  EXPECT_GE(within, 0.99 * bins) << within << " of " << bins << " bins within |z| < 4";
  fs::remove_all(sim);
  fs::remove_all(acq);
}

// The faint tail without bias (no floor from dark subtraction, censoring or noise-dependent
// weights): every bin of a 0.25 mm capture against the truth averaged over the same pixels, the
// truth's own Monte Carlo error and the calibration's in the standard error.
class ProfileWithoutBias : public ::testing::TestWithParam<const char*> {};

TEST_P(ProfileWithoutBias, EveryBinAgreesWithTheTruthDownToTheNoise) {
  const std::string name = GetParam();
  const fs::path sim = fresh_dir("bias-sim-" + name), acq = fresh_dir("bias-acq-" + name);
  SimulateOptions o;
  o.material = materials::load_material(name);
  o.transport.photons = 40000;
  o.transport.size = 128;
  o.transport.pixel_mm = 0.25;
  o.transport.threads = 2;
  o.transport.seed = 5;  // drives the camera noise too
  run_simulation(o, sim);
  const AcquireSummary summary = run_acquire(sim / "capture.json", acq, AcquireOptions{});
  ASSERT_TRUE(summary.calibrated);
  const Profile profile = read_profile(acq / "profile.json");
  const imaging::ImageRgb truth = imaging::read_exr(sim / "truth_radiance.exr");
  const imaging::ImageRgb truth_se = imaging::read_exr(sim / "truth_radiance_se.exr");
  int bins = 0, within3 = 0, tail = 0;
  double worst = 0, tail_z = 0;
  for (std::size_t b = 0; b < profile.radial.size(); ++b) {
    for (int c = 0; c < 3; ++c) {
      const BinnedTruth t = bin_truth(profile, b, c, truth, &truth_se);
      const double sum = t.sum, se2 = t.se2;
      const int n = t.n;
      if (n != profile.radial.count[c][b]) continue;  // a masked pixel changed the set
      const double expected = std::numbers::pi * sum / n;
      const double value = profile.radial.value[c][b];
      const double se = std::sqrt(std::pow(profile.radial.standard_error[c][b], 2) +
                                  std::pow(std::numbers::pi * std::sqrt(se2) / n, 2) +
                                  std::pow(0.01 * expected, 2));  // calibration, ~0.3-1%
      const double z = (value - expected) / se;
      ++bins;
      within3 += std::abs(z) < 3;
      worst = std::max(worst, std::abs(z));
      // The faint tail, where a floor would show: the truth below 1e-4 of the bin nearest the beam.
      if (expected < 1e-4 * profile.radial.value[c][0]) ++tail, tail_z += z;
    }
  }
  EXPECT_GT(bins, 200);
  EXPECT_GE(within3, 0.99 * bins) << within3 << " of " << bins << " bins within 3 SE";
  EXPECT_LT(worst, 4.5);
  if (tail > 10) {
    // No floor: the tail's mean z is noise, |mean| < 3 / sqrt(n) (a floor made it ~+3 or more).
    EXPECT_LT(std::abs(tail_z / tail), 3.0 / std::sqrt(double(tail)))
        << name << ": mean z over " << tail << " faint bins";
  }
  fs::remove_all(sim);
  fs::remove_all(acq);
}

INSTANTIATE_TEST_SUITE_P(Materials, ProfileWithoutBias,
                         ::testing::Values("skin1", "marble", "ketchup"));
}  // namespace
}  // namespace lucent::acquire
