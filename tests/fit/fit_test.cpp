#include "lucent/fit/fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "lucent/core/error.h"
#include "lucent/materials/dipole.h"
#include "lucent/materials/directional_dipole.h"
#include "lucent/materials/fresnel.h"
#include "lucent/materials/profile_table.h"

namespace lucent::fit {
namespace {

using materials::Medium;

// A radial profile made by the model itself (point samples, no noise): what the camera would record
// at normal incidence, pi L / P = F_t F_t R_d (dipole), F_t F_t pi S_d (ddipole) or F_t times the
// transport table's radiance per unit power entering (tabulated).
ProfileData model_profile(const materials::Material& m, FitModel model, int bins = 150) {
  ProfileData d;
  d.source = "model:" + m.name;
  d.eta = m.ior;
  const double ft = materials::fresnel_transmittance(1.0, m.ior);
  double r_min = INFINITY, r_max = 0;
  for (int c = 0; c < 3; ++c) {
    const auto coeffs = materials::derive_coefficients(m.medium(c));
    d.channels[c] = coeffs.scatters();
    if (!coeffs.scatters()) continue;
    r_min = std::min(r_min, 0.2 / coeffs.sigma_t_reduced);
    r_max = std::max(r_max, std::min(8.0 / coeffs.sigma_tr, 400.0 / coeffs.sigma_t_reduced));
  }
  for (int i = 0; i < bins; ++i) {
    const double r = r_min * std::pow(r_max / r_min, double(i) / (bins - 1));
    d.radial.r_mm.push_back(r);
    d.radial.r_inner_mm.push_back(r);
    d.radial.r_outer_mm.push_back(r);
    for (int c = 0; c < 3; ++c) {
      const Medium<double> medium =
          Medium<double>::from_reduced(m.sigma_a[c], m.sigma_s_reduced[c], m.ior);
      double v = 0;
      if (d.channels[c]) {
        if (model == FitModel::kDipole) {
          v = materials::StandardDipole<double>(medium).R_d(r);
        } else if (model == FitModel::kTabulated) {
          // The shipped table's radiance along the normal, per unit power entering.
          v = materials::radial_profile_value(m, c, materials::DiffusionModel::kTabulated,
                                              materials::TableQuantity::kRadiance, r) /
              ft;
        } else {
          const materials::Vec3<double> up(0, 0, 1);
          v = std::numbers::pi * materials::DirectionalDipole<double>(medium).S_d(
                                     materials::Vec3<double>::Zero(), up, up, {r, 0, 0}, up);
        }
      }
      d.radial.value[c].push_back(ft * ft * v);
      d.radial.standard_error[c].push_back(0.01 * ft * ft * v + 1e-300);
    }
  }
  return d;
}

class ExactRecovery : public ::testing::TestWithParam<std::string> {};

TEST_P(ExactRecovery, BothModelsFromStartValuesTenTimesOff) {
  const materials::Material m = materials::load_material(GetParam());
  for (FitModel model : {FitModel::kDipole, FitModel::kDirectionalDipole}) {
    FitOptions o;
    o.model = model;
    o.exclude_radius_mm = 0;
    o.quality = Quality::kAccurate;
    std::array<std::array<double, 2>, 3> start{};
    for (int c = 0; c < 3; ++c) start[c] = {10 * m.sigma_a[c], 10 * m.sigma_s_reduced[c]};
    o.start = start;
    const FitResult r = fit_profiles({model_profile(m, model)}, o);
    EXPECT_TRUE(r.chosen.converged) << r.chosen.message;
    for (int c = 0; c < 3; ++c) {
      if (!materials::derive_coefficients(m.medium(c)).scatters()) continue;
      EXPECT_NEAR(r.chosen.channels[c].sigma_a, m.sigma_a[c], 1e-4 * m.sigma_a[c])
          << GetParam() << " channel " << c << " model " << int(model);
      EXPECT_NEAR(r.chosen.channels[c].sigma_s_reduced, m.sigma_s_reduced[c],
                  1e-4 * m.sigma_s_reduced[c])
          << GetParam() << " channel " << c << " model " << int(model);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Bundled, ExactRecovery,
                         ::testing::ValuesIn(materials::library_material_names()));

// The adequacy verdicts say one thing: adequate_model is the first adequate entry or "none" when
// no entry is adequate; the fallback is the adequate model or, failing one, the closest; every note
// that calls a model adequate or not agrees with its entry; bands are from the bar up.
void expect_adequacy_agrees(const FitResult& r) {
  const ModelAdequacy* first = nullptr;
  for (const ModelAdequacy& a : r.adequacy) {
    if (a.adequate && !first) first = &a;
    EXPECT_GE(a.tolerance, ModelAdequacy::kBar);
    EXPECT_EQ(a.adequate, a.tolerance <= ModelAdequacy::kBar && std::isfinite(a.beyond_mm));
    for (const std::string& note : r.notes) {
      if (note.rfind(to_string(a.model) + " with these coefficients", 0) != 0) continue;
      EXPECT_EQ(note.find("not adequate") == std::string::npos &&
                    note.find("more than") == std::string::npos,
                a.adequate)
          << note;
    }
  }
  EXPECT_EQ(r.adequate_model, first ? to_string(first->model) : std::string("none"));
  EXPECT_FALSE(r.fallback_model.empty());
  if (first) EXPECT_EQ(r.fallback_model, r.adequate_model);
}

TEST(Fit, AdequacyIsNoneWhenNoDipoleHoldsAndTheFallbackIsSaid) {
  // The transport table's own profiles (point samples from 0.2 mean free paths): near the beam
  // both dipoles are tens of percent off transport (measured: skin1 210% and 540% worst, more than
  // 50% off over much of the data; marble within 10% only beyond 27-32 mm), so neither is
  // adequate at 3% and the answer is "none", with the closest named for renderers.
  for (const char* name : {"skin1", "marble"}) {
    const materials::Material m = materials::load_material(name);
    FitOptions o;
    const FitResult r = fit_profiles({model_profile(m, FitModel::kTabulated)}, o);
    EXPECT_TRUE(r.chosen.converged) << name << ": " << r.chosen.message;
    ASSERT_EQ(r.adequacy.size(), 2u) << name;
    expect_adequacy_agrees(r);
    EXPECT_EQ(r.adequate_model, "none") << name;
    EXPECT_FALSE(r.adequacy[0].adequate || r.adequacy[1].adequate) << name;
  }
}

TEST(Fit, AutoFitsTheTabulatedModelAndJudgesTheDipolesAgainstIt) {
  const materials::Material m = materials::load_material("potato");
  // The dipole's own profile: the tabulated model (exact transport) cannot follow it within the
  // profile's standard errors, so the fit is not called converged (it says so) and is kept only
  // with allow_unconverged; the machinery of choosing and judging models is what is tested here.
  FitOptions o;
  o.allow_unconverged = true;
  const FitResult r = fit_profiles({model_profile(m, FitModel::kDipole)}, o);
  EXPECT_FALSE(r.chosen.converged);
  EXPECT_NE(r.chosen.message.find("misses the data"), std::string::npos) << r.chosen.message;
  EXPECT_EQ(r.chosen.model, FitModel::kTabulated) << r.reason;
  ASSERT_EQ(r.candidates.size(), 3u);
  EXPECT_EQ(r.candidates[1].model, FitModel::kDipole);
  ASSERT_EQ(r.adequacy.size(), 2u);
  expect_adequacy_agrees(r);
  // The dipole candidate carries its difference from the tabulated fit as a systematic.
  for (int c = 0; c < 3; ++c) {
    const ChannelFit& d = r.candidates[1].channels[c];
    EXPECT_NEAR(d.sd_sys_sigma_a, std::abs(d.sigma_a - r.chosen.channels[c].sigma_a), 1e-15);
    EXPECT_GE(d.sd_sigma_a, d.sd_stat_sigma_a);
    EXPECT_NEAR(d.sd_sigma_a, std::hypot(d.sd_stat_sigma_a, d.sd_sys_sigma_a), 1e-15);
  }
}

// The tabulated model's systematic comes from refits against shaken tables and a changed model,
// capped at a few iterations (they start at the answer): the capped SDs must stay within 10% of
// those of refits run to convergence, or the cap changes the reported uncertainty. The directional
// dipole's profile, which the tabulated model does not quite follow, makes refits that need more
// than one step (capped at 1, the systematic of sigma_s' moves by 13-14%).
TEST(Fit, CappedSystematicRefitsGiveTheConvergedRefitsSystematic) {
  const materials::Material m = materials::load_material("marble");
  FitOptions o;
  o.model = FitModel::kTabulated;
  o.allow_unconverged = true;
  const ProfileData d = model_profile(m, FitModel::kDirectionalDipole);
  const FitResult capped = fit_profiles({d}, o);
  o.systematic_refit_iterations = 0;
  const FitResult converged = fit_profiles({d}, o);
  for (int c = 0; c < 3; ++c) {
    const ChannelFit &a = capped.chosen.channels[c], &b = converged.chosen.channels[c];
    EXPECT_EQ(a.sigma_a, b.sigma_a);  // the answer itself is not refitted
    ASSERT_GT(b.sd_sys_sigma_a, 0) << c;
    ASSERT_GT(b.sd_sys_sigma_s_reduced, 0) << c;
    EXPECT_NEAR(a.sd_sys_sigma_a / b.sd_sys_sigma_a, 1.0, 0.1) << c;
    EXPECT_NEAR(a.sd_sys_sigma_s_reduced / b.sd_sys_sigma_s_reduced, 1.0, 0.1) << c;
  }
}

TEST(Fit, ProgressNamesEveryStageOfADefaultFitInOrder) {
  const materials::Material m = materials::load_material("potato");
  FitOptions o;
  o.allow_unconverged = true;  // the dipole's own profile: see the test above
  std::vector<std::pair<std::string, double>> stages;
  o.progress = [&](const std::string& stage, double done) { stages.emplace_back(stage, done); };
  fit_profiles({model_profile(m, FitModel::kDipole)}, o);
  const std::vector<std::string> expected{
      "fitting the standard dipole", "fitting the tabulated model",
      "fitting the directional dipole", "the table's systematic (bootstrap and accuracy refits)",
      "the adequacy of the dipoles and the g systematic"};
  ASSERT_EQ(stages.size(), expected.size());
  for (std::size_t i = 0; i < stages.size(); ++i) {
    EXPECT_EQ(stages[i].first, expected[i]);
    EXPECT_GE(stages[i].second, 0.0);
    EXPECT_LT(stages[i].second, 1.0);
    if (i > 0) EXPECT_GT(stages[i].second, stages[i - 1].second) << stages[i].first;
  }
}

TEST(Fit, WithoutAnAccurateModelAutoKeepsTheSimplerDiffusionModel) {
  // eta 2 lies outside the shipped table (1.0-1.6): the choice between the dipoles is the data's.
  materials::Material m = materials::load_material("potato");
  m.ior = 2.0;
  FitOptions o;
  o.exclude_radius_mm = 0;
  const FitResult from_dipole = fit_profiles({model_profile(m, FitModel::kDipole)}, o);
  EXPECT_EQ(from_dipole.chosen.model, FitModel::kDipole) << from_dipole.reason;
  EXPECT_NE(from_dipole.reason.find("no accurate model"), std::string::npos) << from_dipole.reason;
  const FitResult from_ddipole = fit_profiles({model_profile(m, FitModel::kDirectionalDipole)}, o);
  EXPECT_EQ(from_ddipole.chosen.model, FitModel::kDirectionalDipole) << from_ddipole.reason;
  EXPECT_EQ(from_ddipole.candidates.size(), 2u);
}

TEST(Fit, RelativeProfileRecoversTheScale) {
  const materials::Material m = materials::load_material("skin1");
  ProfileData d = model_profile(m, FitModel::kDipole);
  for (int c = 0; c < 3; ++c) {
    for (double& v : d.radial.value[c]) v *= 37.0;
    for (double& v : d.radial.standard_error[c]) v *= 37.0;
  }
  d.calibrated = false;
  FitOptions o;
  o.model = FitModel::kDipole;
  o.exclude_radius_mm = 0;
  const FitResult r = fit_profiles({d}, o);
  EXPECT_NEAR(r.chosen.scale, 37.0, 1e-3 * 37.0);
  EXPECT_NEAR(r.chosen.channels[1].sigma_a, m.sigma_a[1], 1e-3 * m.sigma_a[1]);
}

TEST(Fit, UncertaintyIsReportedAndFiniteForAGoodFit) {
  const FitResult r =
      fit_profiles({model_profile(materials::load_material("marble"), FitModel::kDipole)},
                   FitOptions{.model = FitModel::kDipole});
  for (const ChannelFit& c : r.chosen.channels) {
    EXPECT_GT(c.sd_sigma_a, 0.0);
    EXPECT_GT(c.sd_sigma_s_reduced, 0.0);
    EXPECT_LT(c.sd_sigma_a, c.sigma_a);
    EXPECT_TRUE(std::abs(c.correlation) <= 1.0);
  }
  EXPECT_TRUE(r.chosen.undetermined.empty());
}

TEST(Fit, ScaleAndAlbedoTogetherAreUndeterminedInTheFarFieldOnly) {
  // Far-field samples of a relative profile fix sigma_tr but not sigma_a and sigma_s' apart from
  // the scale: the fit must say so rather than crash or report tiny errors.
  const materials::Material m = materials::load_material("marble");
  ProfileData d = model_profile(m, FitModel::kDipole);
  d.calibrated = false;
  d.channels = {true, false, false};
  FitOptions o;
  o.model = FitModel::kDipole;
  o.exclude_radius_mm = 60.0;  // only r > 60 mm: pure exponential tail
  o.allow_unconverged = true;
  const FitResult r = fit_profiles({d}, o);
  EXPECT_FALSE(r.chosen.undetermined.empty());
}

TEST(Fit, UnconvergedFitSaysSoUnlessAllowed) {
  const materials::Material m = materials::load_material("marble");
  FitOptions o;
  o.model = FitModel::kDipole;
  o.max_iterations = 1;
  std::array<std::array<double, 2>, 3> start{};
  for (int c = 0; c < 3; ++c) start[c] = {30 * m.sigma_a[c], 0.1 * m.sigma_s_reduced[c]};
  o.start = start;
  ProfileData d = model_profile(m, FitModel::kDipole);
  for (int c = 0; c < 3; ++c) {  // a profile the model cannot fit exactly: the solver must iterate
    for (std::size_t i = 0; i < d.radial.size(); ++i)
      d.radial.value[c][i] *= 1 + 0.05 * std::sin(double(i));
  }
  try {
    fit_profiles({d}, o);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("did not converge"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("best values"), std::string::npos) << e.what();
  }
  o.allow_unconverged = true;
  const FitResult r = fit_profiles({d}, o);
  EXPECT_FALSE(r.chosen.converged);
}

// A 2D oblique profile made by the directional dipole itself (pixel centres, no noise).
ProfileData oblique_profile(const materials::Material& m, double incidence_deg,
                            double azimuth_deg) {
  ProfileData d;
  d.source = "model-oblique";
  d.eta = m.ior;
  d.incidence_polar_deg = incidence_deg;
  d.incidence_azimuth_deg = azimuth_deg;
  const double th = incidence_deg * std::numbers::pi / 180,
               ph = azimuth_deg * std::numbers::pi / 180;
  const materials::Vec3<double> w_i(-std::sin(th) * std::cos(ph), -std::sin(th) * std::sin(ph),
                                    std::cos(th));
  const materials::Vec3<double> up(0, 0, 1);
  const double ft = materials::fresnel_transmittance(std::cos(th), m.ior) *
                    materials::fresnel_transmittance(1.0, m.ior);
  Samples2d s;
  for (int j = 0; j < 24; ++j) {
    for (int i = 0; i < 24; ++i) {
      const double x = (i - 11.5) * 0.5, y = (j - 11.5) * 0.5;
      s.x_mm.push_back(x);
      s.y_mm.push_back(y);
      for (int c = 0; c < 3; ++c) {
        const double v = ft * std::numbers::pi *
                         materials::DirectionalDipole<double>(m.medium(c))
                             .S_d(materials::Vec3<double>::Zero(), up, w_i, {x, y, 0.0}, up);
        s.value[c].push_back(v);
        s.standard_error[c].push_back(0.01 * v + 1e-300);
      }
    }
  }
  d.samples_2d = s;
  return d;
}

TEST(Fit, ObliqueCapturesFitJointlyWithTheDirectionalDipole) {
  const materials::Material m = materials::load_material("skin2");
  FitOptions o;
  o.model = FitModel::kAuto;
  o.exclude_radius_mm = 0;
  // Auto takes the accurate model for oblique 2D data: the table-corrected directional dipole.
  const FitResult automatic =
      fit_profiles({oblique_profile(m, 45, 0), oblique_profile(m, 30, 90)}, o);
  EXPECT_EQ(automatic.chosen.model, FitModel::kTabulated) << automatic.reason;
  EXPECT_NE(automatic.reason.find("oblique"), std::string::npos) << automatic.reason;
  // These data are the directional dipole's own: asked for, it recovers them exactly.
  o.model = FitModel::kDirectionalDipole;
  const FitResult r = fit_profiles({oblique_profile(m, 45, 0), oblique_profile(m, 30, 90)}, o);
  EXPECT_EQ(r.chosen.model, FitModel::kDirectionalDipole) << r.reason;
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(r.chosen.channels[c].sigma_a, m.sigma_a[c], 1e-4 * m.sigma_a[c]);
    EXPECT_NEAR(r.chosen.channels[c].sigma_s_reduced, m.sigma_s_reduced[c],
                1e-4 * m.sigma_s_reduced[c]);
    EXPECT_EQ(r.chosen.channels[c].samples, 2 * 24 * 24);
  }
}

TEST(Fit, RobustLossShrugsOffAnOutlier) {
  const materials::Material m = materials::load_material("marble");
  ProfileData d = model_profile(m, FitModel::kDipole, 60);
  for (int c = 0; c < 3; ++c) d.radial.value[c][30] *= 3.0;  // a hot pixel: 200 standard errors off
  FitOptions o;
  o.model = FitModel::kDipole;
  o.exclude_radius_mm = 0;
  const FitResult plain = fit_profiles({d}, o);
  o.loss = LossKind::kHuber;
  o.loss_scale = 2.0;
  const FitResult robust = fit_profiles({d}, o);
  for (int c = 0; c < 3; ++c) {
    const double plain_error = std::abs(plain.chosen.channels[c].sigma_a / m.sigma_a[c] - 1);
    const double robust_error = std::abs(robust.chosen.channels[c].sigma_a / m.sigma_a[c] - 1);
    EXPECT_LT(robust_error, 0.2 * plain_error) << "channel " << c;
    EXPECT_LT(robust_error, 1e-3) << "channel " << c;
  }
}

TEST(Fit, IndexOfRefractionCanBeFitted) {
  // The ddipole's shape at oblique incidence depends on eta (refraction of the beam, C_phi, C_E): a
  // noise-free oblique profile pins it.
  const materials::Material m = materials::load_material("apple");
  FitOptions o;
  o.model = FitModel::kDirectionalDipole;
  o.exclude_radius_mm = 0;
  o.fit_ior = true;
  o.ior = 1.45;  // start away from the truth, 1.3
  ProfileData d = oblique_profile(m, 50, 0);
  d.eta.reset();
  const FitResult r = fit_profiles({d}, o);
  EXPECT_NEAR(r.chosen.eta, 1.3, 1e-3);
  EXPECT_GT(r.chosen.sd_eta, 0.0);
}

TEST(Fit, BadInputs) {
  const materials::Material m = materials::load_material("marble");
  EXPECT_THROW(fit_profiles({}, FitOptions{}), Error);
  ProfileData empty;
  empty.source = "empty.csv";
  empty.eta = 1.5;
  try {
    fit_profiles({empty}, FitOptions{});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("empty"), std::string::npos) << e.what();
  }
  ProfileData few = model_profile(m, FitModel::kDipole, 150);
  FitOptions o;
  o.exclude_radius_mm = 1e6;  // nothing left
  try {
    fit_profiles({few}, o);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("usable samples"), std::string::npos) << e.what();
  }
  ProfileData nan = model_profile(m, FitModel::kDipole);
  nan.radial.value[1][10] = std::nan("");
  EXPECT_THROW(fit_profiles({nan}, FitOptions{}), Error);
  ProfileData no_eta = model_profile(m, FitModel::kDipole);
  no_eta.eta.reset();
  try {
    fit_profiles({no_eta}, FitOptions{});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--ior"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace lucent::fit
