// The default fit (tabulated) against Monte Carlo truth: the simulator's exitance of a material,
// written as lucent simulate writes it and read back as lucent fit reads it (the chain closes).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "lucent/acquire/photon_transport.h"
#include "lucent/fit/fit.h"
#include "lucent/materials/material.h"
#include "lucent/materials/profile_table.h"

namespace lucent::fit {
namespace {

namespace fs = std::filesystem;

TEST(FitMonteCarlo, DefaultFitOfSimulatedExitanceRecoversTheTruthWithinItsTotalUncertainty) {
  const materials::Material m = materials::load_material("skin1");
  acquire::PhotonTransportOptions o;
  for (int c = 0; c < 3; ++c) o.media[std::size_t(c)] = m.medium(c);
  o.photons = 1000000;  // the truth: >= 1e6 photons per channel (about 4 s here)
  o.image = false;
  o.max_radius_mm = 40;
  o.seed = 11;
  const acquire::PhotonTransportResult r = acquire::simulate_photon_transport(o);
  const fs::path csv = fs::temp_directory_path() / ("lucent_fit_mc_" + std::to_string(::getpid()) + ".csv");
  std::ofstream(csv) << acquire::exitance_csv(r);
  const ProfileData data = load_profile_data(csv);
  fs::remove(csv);
  ASSERT_TRUE(data.eta.has_value()) << "eta read from the CSV's comment lines";
  EXPECT_DOUBLE_EQ(*data.eta, m.ior);
  EXPECT_TRUE(data.per_incident_power);
  const FitResult f = fit_profiles({data}, FitOptions{});
  EXPECT_EQ(f.chosen.model, FitModel::kTabulated) << f.reason;
  for (int c = 0; c < 3; ++c) {
    const ChannelFit& ch = f.chosen.channels[c];
    for (auto [value, sd, truth] : {std::tuple{ch.sigma_a, ch.sd_sigma_a, m.sigma_a[c]},
                                    std::tuple{ch.sigma_s_reduced, ch.sd_sigma_s_reduced,
                                               m.sigma_s_reduced[c]}}) {
      // The targets: within 2% (every skin1 channel has alpha' >= 0.5) and the truth
      // within 3 reported total SDs. (At 3e5 photons blue sigma_s' came out +1.2..+2.7% over
      // three seeds, z up to 3.1: a small-sample bias of the fit that is gone at 1e6, +0.4%.)
      EXPECT_LT(std::abs(value - truth), 3 * sd) << "channel " << c << " " << value << " +- " << sd
                                                 << " truth " << truth;
      EXPECT_LT(std::abs(value / truth - 1), 0.02) << "channel " << c;
    }
  }
}

TEST(FitMonteCarlo, ProfileCsvFeedsTheFitUnchanged) {
  // lucent profile's CSV (tabulated exitance, eta in the comment line) fits back to its material.
  const materials::Material m = materials::load_material("potato");
  materials::RadialProfileOptions po;
  po.model = materials::DiffusionModel::kTabulated;
  for (int i = 0; i < 120; ++i) po.r_mm.push_back(0.05 * std::pow(1.05, i));
  const fs::path csv = fs::temp_directory_path() / ("lucent_fit_profile_" + std::to_string(::getpid()) + ".csv");
  std::ofstream(csv) << materials::radial_profile_csv(m, po);
  const ProfileData data = load_profile_data(csv);
  fs::remove(csv);
  ASSERT_TRUE(data.eta.has_value());
  EXPECT_FALSE(data.per_incident_power);
  const FitResult f = fit_profiles({data}, FitOptions{});
  EXPECT_EQ(f.chosen.model, FitModel::kTabulated);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(f.chosen.channels[c].sigma_a, m.sigma_a[c], 2e-3 * m.sigma_a[c]) << c;
    EXPECT_NEAR(f.chosen.channels[c].sigma_s_reduced, m.sigma_s_reduced[c],
                2e-3 * m.sigma_s_reduced[c])
        << c;
  }
}

}  // namespace
}  // namespace lucent::fit
