#include "lucent/acquire/photon_transport.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <iostream>
#include <numbers>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "lucent/core/error.h"
#include "lucent/materials/dipole.h"
#include "lucent/materials/fresnel.h"
#include "lucent/materials/material.h"
#include "lucent/materials/quadrature.h"

namespace lucent::acquire {
namespace {

using materials::Medium;

constexpr double kPi = std::numbers::pi;

// Chandrasekhar's H-function for isotropic scattering with single-scattering albedo 0.9, from
// ln H(mu) = -(mu / pi) int_0^(pi/2) ln(1 - omega t cot t) / (cos^2 t + mu^2 sin^2 t) dt, evaluated
// by Simpson's rule on 2e5 panels (converged to all digits shown).
constexpr double kH1Albedo09 = 1.85009852;   // H(1)
constexpr double kH05Albedo09 = 1.55603380;  // H(0.5)

// One channel of `medium`, semi-infinite, normal incidence, no image: the common case.
PhotonTransportOptions one_channel(const Medium<double>& medium, std::uint64_t photons) {
  PhotonTransportOptions o;
  o.media[0] = medium;
  o.channels = {true, false, false};
  o.photons = photons;
  o.image = false;
  o.threads = 2;
  return o;
}

double energy_sum(const ChannelTransportResult& c) {
  return c.diffuse_reflectance.value + c.specular_reflectance.value + c.transmittance.value +
         c.absorbed.value;
}

TEST(PhotonTransport, MatchedIndexIsotropicReflectanceIsChandrasekharsValue) {
  // Semi-infinite, eta = 1, isotropic, albedo 0.9, normal incidence: the plane albedo is
  // 1 - H(1) sqrt(1 - omega) = 0.41495 (van de Hulst; MCML's own validation case).
  const auto result = simulate_photon_transport(one_channel({1.0, 9.0, 0.0, 1.0}, 2'000'000));
  const auto& c = result.channels[0];
  const double expected = 1 - kH1Albedo09 * std::sqrt(0.1);
  EXPECT_NEAR(expected, 0.41495, 1e-5);
  EXPECT_LT(3 * c.diffuse_reflectance.standard_error, 0.003 * expected);
  EXPECT_NEAR(c.diffuse_reflectance.value, expected, 3 * c.diffuse_reflectance.standard_error);
  EXPECT_EQ(c.specular_reflectance.value, 0.0);
  EXPECT_EQ(c.transmittance.value, 0.0);
  std::cout << "[ measured ] R_d = " << c.diffuse_reflectance.value << " +- "
            << c.diffuse_reflectance.standard_error << " (H-function " << expected << ")\n";
}

TEST(PhotonTransport, AnisotropicFiniteSlabMatchesVanDeHulst) {
  // MCML's validation slab (Wang, Jacques, Zheng 1995): sigma_a = 1/mm, sigma_s = 9/mm, g = 0.75,
  // eta = 1, 0.2 mm thick: R_d = 0.09739, T_t = 0.66096 (van de Hulst's tables).
  auto o = one_channel({1.0, 9.0, 0.75, 1.0}, 1'000'000);
  o.thickness_mm = 0.2;
  const auto c = simulate_photon_transport(o).channels[0];
  EXPECT_NEAR(c.diffuse_reflectance.value, 0.09739,
              3 * c.diffuse_reflectance.standard_error + 1e-5);
  EXPECT_NEAR(c.transmittance.value, 0.66096, 3 * c.transmittance.standard_error + 1e-5);
}

TEST(PhotonTransport, NonScatteringSlabMatchesTheMultipleReflectionSeries) {
  // eta = 1.5, absorbing only, 0.2 mm thick at 1/mm: the beam bounces between the faces.
  // R = R0 + (1 - R0)^2 R0 t^2 / (1 - R0^2 t^2), T = (1 - R0)^2 t / (1 - R0^2 t^2), t = e^-0.2.
  auto o = one_channel({1.0, 0.0, 0.0, 1.5}, 400'000);
  o.thickness_mm = 0.2;
  const auto c = simulate_photon_transport(o).channels[0];
  const double R0 = 0.04, t = std::exp(-0.2);
  const double denominator = 1 - R0 * R0 * t * t;
  EXPECT_DOUBLE_EQ(c.specular_reflectance.value, R0);
  EXPECT_NEAR(c.diffuse_reflectance.value, (1 - R0) * (1 - R0) * R0 * t * t / denominator,
              4 * c.diffuse_reflectance.standard_error);
  EXPECT_NEAR(c.transmittance.value, (1 - R0) * (1 - R0) * t / denominator,
              4 * c.transmittance.standard_error);
  EXPECT_LE(c.mean_interactions, 1.0);  // each photon is absorbed at its first collision
}

TEST(PhotonTransport, EnergyBalancesPhotonByPhoton) {
  double worst = 0;
  for (const double thickness : {1.0, std::numeric_limits<double>::infinity()}) {
    for (const auto scoring : {BoundaryScoring::kStochastic, BoundaryScoring::kSplit}) {
      PhotonTransportOptions o;
      o.media = {Medium<double>{0.05, 3.0, 0.8, 1.4}, Medium<double>{0.5, 2.0, 0.0, 1.4},
                 Medium<double>{2.0, 0.5, -0.3, 1.4}};
      o.thickness_mm = thickness;
      o.incidence_deg = 40;
      o.azimuth_deg = 30;
      o.photons = 20'000;
      o.threads = 2;
      o.size = 32;
      o.boundary_scoring = scoring;
      const auto result = simulate_photon_transport(o);
      for (const auto& c : result.channels) {
        EXPECT_NEAR(energy_sum(c), 1.0, 1e-6) << "thickness " << thickness;
        worst = std::max(worst, std::abs(energy_sum(c) - 1));
        EXPECT_GT(c.absorbed.value, 0.0);
        EXPECT_GT(c.diffuse_reflectance.value, 0.0);
        if (std::isfinite(thickness)) {
          EXPECT_GT(c.transmittance.value, 0.0);
        } else {
          EXPECT_EQ(c.transmittance.value, 0.0);
        }
      }
    }
  }
  std::cout << "[ measured ] worst |reflected + specular + transmitted + absorbed - 1| = " << worst
            << "\n";
}

TEST(PhotonTransport, TotalsAgreeWithTheStandardDipoleForHighAlbedoMaterials) {
  // The dipole's R_tot is per unit power *entering* the sample; the simulator's diffuse reflectance
  // is per unit incident power, so it is divided by 1 - specular before comparing.
  for (const std::string name : {"marble", "skimmilk", "wholemilk", "cream", "apple"}) {
    const materials::Material material = materials::load_material(name);
    for (int channel = 0; channel < 2; ++channel) {
      const Medium<double> medium = material.medium(channel);
      const auto c = simulate_photon_transport(one_channel(medium, 12'000)).channels[0];
      const double simulated = c.diffuse_reflectance.value / (1 - c.specular_reflectance.value);
      const double dipole = materials::StandardDipole<double>(medium).total_diffuse_reflectance();
      EXPECT_NEAR(simulated, dipole, 0.03 * dipole) << name << " channel " << channel;
      EXPECT_LT(c.diffuse_reflectance.standard_error, 0.005 * simulated) << name;
      std::cout << "[ measured ] " << name << " channel " << channel << ": MC " << simulated
                << " +- " << c.diffuse_reflectance.standard_error << ", dipole " << dipole
                << ", ratio " << simulated / dipole << ", " << c.mean_interactions
                << " interactions/photon\n";
    }
  }
}

TEST(PhotonTransport, MarbleRadialExitanceFollowsTheDipoleBeyondFiveMillimetres) {
  // Compared over annuli 5-10, 10-15 and 15-20 mm (unions of whole bins, the dipole integrated over
  // exactly the same radii) rather than bin by bin: single bins out there are 0.5-1 mm wide and
  // noisy, while the annuli carry enough weight for a ~1-2% standard error at 60k photons. Beyond
  // ~5 mean free paths the diffusion approximation is expected to hold, so 10% is the tolerance.
  const Medium<double> marble = materials::load_material("marble").medium(0);
  const auto result = simulate_photon_transport(one_channel(marble, 60'000));
  const auto& c = result.channels[0];
  const materials::StandardDipole<double> dipole(marble);
  const double entering = 1 - c.specular_reflectance.value;
  for (const auto& [from, to] : {std::pair{5.0, 10.0}, {10.0, 15.0}, {15.0, 20.0}}) {
    double simulated = 0, variance = 0, inner = -1, outer = 0;
    for (std::size_t b = 0; b < result.bins.size(); ++b) {
      const ExitanceBin& bin = result.bins[b];
      if (bin.r_centre_mm < from || bin.r_centre_mm >= to) continue;
      if (inner < 0) inner = bin.r_inner_mm;
      outer = bin.r_outer_mm;
      const double area = kPi * (bin.r_outer_mm * bin.r_outer_mm - bin.r_inner_mm * bin.r_inner_mm);
      simulated += c.exitance[b].value * area;
      // Bins of one photon are nearly independent out here (a photon leaves once): add variances.
      variance += std::pow(c.exitance[b].standard_error * area, 2);
    }
    simulated /= entering;
    const double se = std::sqrt(variance) / entering;
    const double model = materials::integrate([&](double r) { return 2 * kPi * r * dipole.R_d(r); },
                                              inner, outer, 1e-10);
    EXPECT_NEAR(simulated / model, 1.0, 0.10) << inner << "-" << outer << " mm";
    EXPECT_LT(se, 0.04 * simulated);
    std::cout << "[ measured ] marble red, " << inner << "-" << outer << " mm: MC " << simulated
              << " +- " << se << ", dipole " << model << ", ratio " << simulated / model << "\n";
  }
}

bool same_channel(const ChannelTransportResult& a, const ChannelTransportResult& b) {
  auto same = [](const Estimate& x, const Estimate& y) {
    return std::memcmp(&x, &y, sizeof(Estimate)) == 0;
  };
  auto same_vectors = [](const auto& x, const auto& y) {
    return x.size() == y.size() &&
           (x.empty() || std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0);
  };
  return a.photons == b.photons && same(a.diffuse_reflectance, b.diffuse_reflectance) &&
         same(a.specular_reflectance, b.specular_reflectance) &&
         same(a.transmittance, b.transmittance) && same(a.absorbed, b.absorbed) &&
         same(a.image_integral, b.image_integral) && same_vectors(a.exitance, b.exitance) &&
         same_vectors(a.image, b.image) &&
         same_vectors(a.image_standard_error, b.image_standard_error) &&
         a.mean_interactions == b.mean_interactions;
}

TEST(PhotonTransport, BitIdenticalForAnyThreadCountAndSeedDependent) {
  PhotonTransportOptions o;
  const materials::Material potato = materials::load_material("potato");
  for (int c = 0; c < 3; ++c) o.media[static_cast<std::size_t>(c)] = potato.medium(c);
  o.media[1].g = 0.5;  // one anisotropic channel
  o.media[1].sigma_s = 1.4;
  o.photons = 4 * kPhotonsPerBatch + 123;  // a partial last batch too
  o.size = 48;
  o.incidence_deg = 30;
  o.seed = 7;
  std::vector<PhotonTransportResult> results;
  for (const int threads : {1, 2, 3}) {
    o.threads = threads;
    results.push_back(simulate_photon_transport(o));
  }
  for (std::size_t run = 1; run < results.size(); ++run) {
    for (std::size_t c = 0; c < 3; ++c) {
      EXPECT_TRUE(same_channel(results[0].channels[c], results[run].channels[c]))
          << "threads " << results[run].threads_used << " channel " << c;
    }
    EXPECT_EQ(exitance_csv(results[0]), exitance_csv(results[run]));
  }
  EXPECT_EQ(results[0].channels[0].photons, o.photons);

  o.seed = 8;
  const auto other = simulate_photon_transport(o);
  for (std::size_t c = 0; c < 3; ++c) {
    EXPECT_FALSE(same_channel(results[0].channels[c], other.channels[c]));
    EXPECT_NE(results[0].channels[c].diffuse_reflectance.value,
              other.channels[c].diffuse_reflectance.value);
  }
}

TEST(PhotonTransport, ChannelsHaveIndependentStreams) {
  // Identical media in two channels must not give identical results (a stream per channel).
  PhotonTransportOptions o;
  o.media = {Medium<double>{0.1, 2.0, 0.0, 1.3}, Medium<double>{0.1, 2.0, 0.0, 1.3},
             Medium<double>{0.1, 2.0, 0.0, 1.3}};
  o.photons = 5000;
  o.image = false;
  o.channels = {true, true, false};
  const auto result = simulate_photon_transport(o);
  EXPECT_NE(result.channels[0].diffuse_reflectance.value,
            result.channels[1].diffuse_reflectance.value);
  EXPECT_EQ(result.channels[2].photons, 0u);
  EXPECT_TRUE(std::isnan(result.channels[2].diffuse_reflectance.value));
}

TEST(PhotonTransport, StochasticAndSplitBoundariesAgree) {
  const Medium<double> potato = materials::load_material("potato").medium(0);
  auto o = one_channel(potato, 40'000);
  const auto stochastic = simulate_photon_transport(o).channels[0];
  o.boundary_scoring = BoundaryScoring::kSplit;
  const auto split = simulate_photon_transport(o).channels[0];
  const double se = std::hypot(stochastic.diffuse_reflectance.standard_error,
                               split.diffuse_reflectance.standard_error);
  EXPECT_NEAR(stochastic.diffuse_reflectance.value, split.diffuse_reflectance.value, 4 * se);
  // Splitting keeps walking the reflected remnant: more interactions per photon.
  EXPECT_GT(split.mean_interactions, stochastic.mean_interactions);
}

// Radiance of the whole imaged surface for eta = 1, isotropic scattering, albedo 0.9, beam along
// the normal (mu_0 = 1), camera at polar cosine mu: int L dA = omega / (4 pi) H(mu) H(mu_0) / (mu +
// mu_0) (Chandrasekhar's reflection function of a semi-infinite medium, per unit incident power).
TEST(PhotonTransport, NextEventImageIntegratesToTheHFunctionRadiance) {
  const double omega = 0.9;
  for (const double view_deg : {0.0, 60.0}) {
    auto o = one_channel({1.0, 9.0, 0.0, 1.0}, 500'000);
    o.image = true;
    o.size = 128;
    o.pixel_mm = 0.05;  // +-3.2 mm = 32 mean free paths: nothing of note leaves the grid
    o.view_deg = view_deg;
    o.view_azimuth_deg = 20;
    const auto c = simulate_photon_transport(o).channels[0];
    const double mu = std::cos(view_deg * kPi / 180);
    const double H_mu = view_deg == 0 ? kH1Albedo09 : kH05Albedo09;
    const double expected = omega / (4 * kPi) * H_mu * kH1Albedo09 / (mu + 1);
    EXPECT_NEAR(c.image_integral.value, expected, 3 * c.image_integral.standard_error)
        << "view " << view_deg;
    EXPECT_LT(c.image_integral.standard_error, 0.002 * expected);
    // The image and its integral are the same sums.
    double sum = 0;
    for (const double v : c.image) sum += v * o.pixel_mm * o.pixel_mm;
    EXPECT_NEAR(sum, c.image_integral.value, 1e-9 * sum);
    std::cout << "[ measured ] view " << view_deg << " deg: int L dA = " << c.image_integral.value
              << " +- " << c.image_integral.standard_error << " sr^-1 (H-function " << expected
              << ")\n";
  }
}

TEST(PhotonTransport, NextEventImageMatchesSingleScatteringAtLowAlbedo) {
  // With albedo 0.001 the image is single scattering to within ~0.2% (measured excess at albedo
  // 0.01: 0.3-1.6%, linear in the albedo as multiple scattering should be). For a semi-infinite
  // sample the first collisions along the refracted beam (cosine mu_0t inside) seen through the
  // refracted camera direction (cosine mu_t) integrate to
  //   int L dA = (1 - R(mu_0)) omega p_HG(d . w_t) T(mu_t) / (eta^2 (mu_t + mu_0t)),
  // which tests the phase function, both refractions and both Fresnel factors of the estimator.
  struct Case {
    double eta, g, incidence_deg, azimuth_deg, view_deg, view_azimuth_deg;
  };
  for (const Case& k : {Case{1.4, 0.6, 30, 0, 50, 180}, Case{1.0, -0.4, 0, 0, 30, 90},
                        Case{1.3, 0.9, 60, 45, 20, 225}}) {
    const double omega = 0.001, sigma_t = 10;
    auto o = one_channel({sigma_t * (1 - omega), sigma_t * omega, k.g, k.eta}, 200'000);
    o.image = true;
    o.size = 64;
    o.pixel_mm = 0.05;
    o.incidence_deg = k.incidence_deg;
    o.azimuth_deg = k.azimuth_deg;
    o.view_deg = k.view_deg;
    o.view_azimuth_deg = k.view_azimuth_deg;
    const auto c = simulate_photon_transport(o).channels[0];

    const double deg = kPi / 180;
    const double sin_0t = std::sin(k.incidence_deg * deg) / k.eta;
    const double mu_0t = std::sqrt(1 - sin_0t * sin_0t);
    const double sin_t = std::sin(k.view_deg * deg) / k.eta;
    const double mu_t = std::sqrt(1 - sin_t * sin_t);
    // d: the beam's direction inside (travelling down); w_t: toward the camera inside (up).
    const double d_dot_w =
        sin_0t * sin_t * std::cos((k.azimuth_deg - k.view_azimuth_deg) * deg) - mu_0t * mu_t;
    const double p = (1 - k.g * k.g) / (4 * kPi * std::pow(1 + k.g * k.g - 2 * k.g * d_dot_w, 1.5));
    const double entering =
        1 - materials::fresnel_reflectance(std::cos(k.incidence_deg * deg), k.eta);
    const double leaving = materials::fresnel_transmittance(mu_t, 1 / k.eta);
    const double expected = entering * omega * p * leaving / (k.eta * k.eta * (mu_t + mu_0t));
    EXPECT_NEAR(c.image_integral.value / expected, 1.0,
                0.005 + 3 * c.image_integral.standard_error / expected)
        << "eta " << k.eta << " g " << k.g;
    std::cout << "[ measured ] single scattering, eta " << k.eta << ", g " << k.g
              << ": MC / formula = " << c.image_integral.value / expected << " +- "
              << c.image_integral.standard_error / expected << "\n";
  }
}

TEST(PhotonTransport, NextEventImageIsRadiallySymmetricAndNearlyLambertian) {
  // Skim milk red (eta 1.3, albedo 0.998): at normal incidence the image must be symmetric under a
  // quarter turn about the entry point: its four quadrants agree away from the centre (the
  // single-scattering delta at the origin sits on the corner of four pixels and goes to one).
  // pi * (integrated radiance) against the exitance inside the same circle is 1 for a Lambertian
  // exit distribution; measured 1.03 for this material (1.055 for marble, 0.93 for the albedo-0.9
  // matched-index medium): the test allows 10%.
  const Medium<double> skim = materials::load_material("skimmilk").medium(0);
  auto o = one_channel(skim, 100'000);
  o.image = true;
  o.size = 128;
  o.pixel_mm = 0.1;
  const auto result = simulate_photon_transport(o);
  const auto& c = result.channels[0];
  const int n = o.size;
  // Quadrant sums over two rings (each holds ~10% of the light; standard error ~1%).
  double worst = 0;
  for (const auto& [r0, r1] : {std::pair{0.3, 1.5}, {1.5, 5.0}}) {
    std::array<double, 4> quadrant{};
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const double x = (i + 0.5 - n / 2.0) * o.pixel_mm, y = (j + 0.5 - n / 2.0) * o.pixel_mm;
        const double r = std::hypot(x, y);
        if (r < r0 || r >= r1) continue;
        quadrant[static_cast<std::size_t>((x > 0) + 2 * (y > 0))] +=
            c.image[static_cast<std::size_t>(j * n + i)];
      }
    }
    const double mean = (quadrant[0] + quadrant[1] + quadrant[2] + quadrant[3]) / 4;
    for (const double q : quadrant) worst = std::max(worst, std::abs(q / mean - 1));
  }
  EXPECT_LT(worst, 0.05);

  const double radius = 0.5 * n * o.pixel_mm;
  double inside = 0;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const double x = (i + 0.5 - n / 2.0) * o.pixel_mm, y = (j + 0.5 - n / 2.0) * o.pixel_mm;
      if (std::hypot(x, y) < radius) {
        inside += c.image[static_cast<std::size_t>(j * n + i)] * o.pixel_mm * o.pixel_mm;
      }
    }
  }
  double exitance_inside = 0;
  for (std::size_t b = 0; b < result.bins.size(); ++b) {
    const auto& bin = result.bins[b];
    if (bin.r_outer_mm > radius + 1e-9) break;
    exitance_inside += c.exitance[b].value * kPi *
                       (bin.r_outer_mm * bin.r_outer_mm - bin.r_inner_mm * bin.r_inner_mm);
  }
  EXPECT_NEAR(kPi * inside / exitance_inside, 1.0, 0.10);
  std::cout << "[ measured ] worst quadrant deviation from the mean " << worst
            << "; pi * int L dA / exitance inside r = " << radius
            << " mm: " << kPi * inside / exitance_inside << "\n";
}

TEST(PhotonTransport, ObliqueIncidenceShiftsTheImageTowardPlusX) {
  const Medium<double> skim = materials::load_material("skimmilk").medium(0);
  for (const double azimuth : {0.0, 90.0}) {
    auto o = one_channel(skim, 20'000);
    o.image = true;
    o.size = 64;
    o.pixel_mm = 0.1;
    o.incidence_deg = 45;
    o.azimuth_deg = azimuth;
    const auto c = simulate_photon_transport(o).channels[0];
    double sum = 0, cx = 0, cy = 0;
    for (int j = 0; j < o.size; ++j) {
      for (int i = 0; i < o.size; ++i) {
        const double v = c.image[static_cast<std::size_t>(j * o.size + i)];
        sum += v;
        cx += v * (i + 0.5 - o.size / 2.0) * o.pixel_mm;
        cy += v * (j + 0.5 - o.size / 2.0) * o.pixel_mm;
      }
    }
    cx /= sum;
    cy /= sum;
    // The beam travels toward +x at azimuth 0 (toward +y at 90): light re-emerges downstream.
    const double along = azimuth == 0 ? cx : cy, across = azimuth == 0 ? cy : cx;
    EXPECT_GT(along, 0.2) << "azimuth " << azimuth;
    EXPECT_LT(std::abs(across), 0.1) << "azimuth " << azimuth;
  }
}

TEST(PhotonTransport, ExitanceBinsAreFineNearTheBeamAndEndAtTheMaximumRadius) {
  const auto bins = exitance_bins(100);
  ASSERT_GT(bins.size(), 100u);
  EXPECT_EQ(bins.front().r_inner_mm, 0.0);
  EXPECT_NEAR(bins.front().r_outer_mm, 0.01, 1e-15);
  EXPECT_NEAR(bins[49].r_outer_mm, 0.5, 1e-12);
  EXPECT_NEAR(bins[50].r_outer_mm - bins[50].r_inner_mm, 0.0105, 1e-12);
  EXPECT_EQ(bins.back().r_outer_mm, 100.0);
  for (std::size_t b = 0; b < bins.size(); ++b) {
    if (b > 0) {
      EXPECT_EQ(bins[b].r_inner_mm, bins[b - 1].r_outer_mm);
    }
    EXPECT_GT(bins[b].r_centre_mm, bins[b].r_inner_mm);
    EXPECT_LT(bins[b].r_centre_mm, bins[b].r_outer_mm);
  }
  EXPECT_NEAR(bins.front().r_centre_mm, 2.0 / 3.0 * 0.01, 1e-15);
  const auto small = exitance_bins(0.25);
  EXPECT_EQ(small.size(), 25u);
  EXPECT_EQ(small.back().r_outer_mm, 0.25);
}

TEST(PhotonTransport, ExitanceCsvCarriesTotalsAndOneRowPerBin) {
  PhotonTransportOptions o;
  o.media = {Medium<double>{0.5, 2.0, 0.0, 1.3}, Medium<double>{0.5, 2.0, 0.0, 1.3},
             Medium<double>{0.5, 2.0, 0.0, 1.3}};
  o.photons = 3000;
  o.image = false;
  o.seed = 42;
  o.max_radius_mm = 10;
  const auto result = simulate_photon_transport(o);
  const std::string csv = exitance_csv(result);
  std::istringstream in(csv);
  std::string line;
  std::vector<std::string> comments;
  while (std::getline(in, line) && line.starts_with("#")) comments.push_back(line);
  EXPECT_EQ(line, "r_mm,R_r,R_g,R_b,se_r,se_g,se_b,r_inner_mm,r_outer_mm");
  std::size_t rows = 0;
  while (std::getline(in, line)) {
    ++rows;
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), 8);
  }
  EXPECT_EQ(rows, result.bins.size());
  auto has = [&](const std::string& token) {
    for (const auto& c : comments) {
      if (c.find(token) != std::string::npos) return true;
    }
    return false;
  };
  EXPECT_TRUE(has("format=lucent-simulated-exitance version=1"));
  EXPECT_TRUE(has("photons=3000,3000,3000"));
  EXPECT_TRUE(has("seed=42"));
  for (const char* key : {"diffuse_reflectance=", "specular_reflectance=", "transmittance=",
                          "absorbed=", "diffuse_reflectance_se=", "absorbed_se="}) {
    EXPECT_TRUE(has(key)) << key;
  }
  // 17 significant digits: the totals read back exactly.
  for (const auto& c : comments) {
    const std::string key = "# diffuse_reflectance=";
    if (!c.starts_with(key)) continue;
    const double red = std::stod(c.substr(key.size(), c.find(',') - key.size()));
    EXPECT_EQ(red, result.channels[0].diffuse_reflectance.value);
  }
}

TEST(PhotonTransport, ProgressReachesTheTotalAndItsExceptionsPropagate) {
  auto o = one_channel({0.5, 2.0, 0.0, 1.3}, 3 * kPhotonsPerBatch);
  o.channels = {true, false, true};
  std::uint64_t last = 0, calls = 0, total_seen = 0;
  simulate_photon_transport(o, [&](std::uint64_t done, std::uint64_t total) {
    EXPECT_GT(done, last);
    last = done;
    total_seen = total;
    ++calls;
  });
  EXPECT_EQ(calls, 6u);
  EXPECT_EQ(last, 2 * o.photons);
  EXPECT_EQ(total_seen, 2 * o.photons);
  EXPECT_THROW(simulate_photon_transport(
                   o, [](std::uint64_t, std::uint64_t) { throw Error("cancelled by the user"); }),
               Error);
}

void expect_rejected(const PhotonTransportOptions& o, const std::string& option) {
  try {
    simulate_photon_transport(o);
    ADD_FAILURE() << "accepted a bad '" << option << "'";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'" + option + "'"), std::string::npos) << e.what();
  }
}

TEST(PhotonTransport, BadOptionsAreRejectedByName) {
  const PhotonTransportOptions good = one_channel({0.1, 1.0, 0.0, 1.3}, 100);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto with = [&](auto change) {
    PhotonTransportOptions o = good;
    change(o);
    return o;
  };
  expect_rejected(with([](auto& o) { o.photons = 0; }), "photons");
  expect_rejected(with([](auto& o) { o.thickness_mm = 0; }), "thickness_mm");
  expect_rejected(with([](auto& o) { o.incidence_deg = 90; }), "incidence_deg");
  expect_rejected(with([](auto& o) { o.incidence_deg = -1; }), "incidence_deg");
  expect_rejected(with([&](auto& o) { o.azimuth_deg = nan; }), "azimuth_deg");
  expect_rejected(with([](auto& o) { o.threads = -1; }), "threads");
  expect_rejected(with([](auto& o) { o.max_radius_mm = 0; }), "max_radius_mm");
  expect_rejected(with([](auto& o) { o.image = true, o.size = 0; }), "size");
  expect_rejected(with([](auto& o) { o.image = true, o.pixel_mm = -0.1; }), "pixel_mm");
  expect_rejected(with([](auto& o) { o.image = true, o.view_deg = 95; }), "view_deg");
  expect_rejected(with([&](auto& o) { o.image = true, o.view_azimuth_deg = nan; }),
                  "view_azimuth_deg");
  expect_rejected(with([](auto& o) { o.channels = {false, false, false}; }), "channels");
  expect_rejected(with([](auto& o) { o.media[0].sigma_a = -0.1; }), "media[0].sigma_a");
  expect_rejected(with([&](auto& o) { o.media[0].sigma_s = nan; }), "media[0].sigma_s");
  expect_rejected(with([](auto& o) { o.media[0].g = 1; }), "media[0].g");
  expect_rejected(with([](auto& o) { o.media[0].eta = 0; }), "media[0].eta");
  // An unselected channel is not simulated, so its medium is not checked.
  EXPECT_NO_THROW(simulate_photon_transport(with([](auto& o) { o.media[2].sigma_a = -1; })));
}

TEST(PhotonTransport, DegenerateMediaStayFinite) {
  // No interaction at all in a semi-infinite sample: the refracted beam is lost to depth.
  const auto empty = simulate_photon_transport(one_channel({0.0, 0.0, 0.0, 1.3}, 100)).channels[0];
  EXPECT_NEAR(empty.transmittance.value, 1 - empty.specular_reflectance.value, 1e-15);
  // Pure absorber: everything that enters is absorbed at the first collision.
  const auto black = simulate_photon_transport(one_channel({5.0, 0.0, 0.0, 1.3}, 100)).channels[0];
  EXPECT_NEAR(black.absorbed.value, 1 - black.specular_reflectance.value, 1e-15);
  EXPECT_EQ(black.diffuse_reflectance.value, 0.0);
  // eta < 1 and a camera beyond the critical angle: no direction inside reaches it.
  auto o = one_channel({0.1, 1.0, 0.0, 0.7}, 200);
  o.image = true;
  o.size = 8;
  o.view_deg = 60;
  const auto dark = simulate_photon_transport(o).channels[0];
  for (const double v : dark.image) EXPECT_EQ(v, 0.0);
  EXPECT_NEAR(energy_sum(dark), 1.0, 1e-9);
}

}  // namespace
}  // namespace lucent::acquire
