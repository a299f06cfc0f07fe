#include "lucent/fit/fit.h"
#include "lucent/materials/oblique.h"

#include <ceres/ceres.h>
#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "fit_solve.h"
#include "fit_start.h"
#include "fit_thickness.h"
#include "fit_uncertainty.h"
#include "lack_of_fit.h"
#include "system_response.h"
#include "lucent/materials/error.h"
#include "lucent/materials/tabulated.h"
#include "lucent/materials/transport_table.h"
#include "lucent/version.h"
#include "model_prediction.h"

namespace lucent::fit {
namespace {

using detail::ModelPerturbation;
using detail::solve;
using detail::start_values;
using detail::StartValues;

const char* kChannelNames[3] = {"R", "G", "B"};

// Shares of a default fit's time before each stage, for the progress line (measured on the bundled
// marble_45deg, a 2D oblique fit of about 12 s; a radial fit takes under a second and shows none).
constexpr double kShareTabulated = 0.03, kShareDirectional = 0.10, kShareTableSystematic = 0.17,
                 kShareAdequacy = 0.42;

std::string model_name(FitModel m) {
  return to_string(m);
}

std::string g_text(double g) {  // 0.917, not std::to_string's 0.917000 cut to 0.91
  std::ostringstream s;
  s << g;
  return s.str();
}

}  // namespace

FitResult fit_profiles(const std::vector<ProfileData>& input, const FitOptions& options) {
  if (options.fit_thickness) return detail::fit_unknown_thickness(input, options);
  // A slab: the thickness the options give every input, or each input's own.
  std::vector<ProfileData> data = input;
  bool slab = false;
  if (options.thickness_mm && !(*options.thickness_mm > 0 && *options.thickness_mm <= 1e4))
    throw Error("--thickness-mm: expected a slab thickness in (0, 10000] mm");
  for (ProfileData& d : data) {
    if (options.thickness_mm) d.thickness_mm = options.thickness_mm;
    if (d.transmitted && !d.thickness_mm)
      throw Error(d.source + ": the far side (side=transmitted) needs the sample's thickness: "
                             "give --thickness-mm");
    slab = slab || d.thickness_mm.has_value();
  }
  if (slab && (options.model == FitModel::kDipole || options.model == FitModel::kDirectionalDipole))
    throw Error("--model " + std::string(options.model == FitModel::kDipole ? "dipole" : "ddipole") +
                ": the diffusion models are of a semi-infinite sample; a slab (--thickness-mm) is "
                "fitted with the tabulated model");
  if (slab && options.fit_ior)
    throw Error("--fit-ior: a slab (--thickness-mm) is fitted at a given index (--ior)");
  // Ceres logs (through glog) a warning with every residual of a rejected trial step that went
  // non-finite; the solver handles those steps itself, and a user should see our one-line errors
  // only.
  static const bool quiet = [] {
    // Fatal only: an evaluation that fails outright comes back as a failed solve (fit_solve.cpp)
    // that the restarts replace, and is named in the result when nothing replaces it.
    FLAGS_minloglevel = google::GLOG_FATAL;
    FLAGS_logtostderr = true;
    return true;
  }();
  (void)quiet;
  const auto report = [&](const char* stage, double done) {
    if (options.progress) options.progress(stage, done);
  };
  if (data.empty()) throw Error("fit: no input profile");
  for (const ProfileData& d : data) {
    if (d.radial.size() == 0 && !(d.samples_2d && d.samples_2d->size() > 0)) {
      throw Error(d.source + ": the profile is empty (no radial bins, no 2D samples)");
    }
    for (int c = 0; c < 3; ++c) {
      for (std::size_t i = 0; i < d.radial.size(); ++i) {
        if (!std::isfinite(d.radial.value[c][i]) || !std::isfinite(d.radial.standard_error[c][i]) ||
            !std::isfinite(d.radial.r_mm[i])) {
          throw Error(d.source + ": radial bin " + std::to_string(i) + " holds NaN or Inf");
        }
      }
    }
  }
  std::optional<double> eta = options.ior;
  if (!eta) eta = data.front().eta;
  // Inputs of one material share one index: two that say otherwise contradict each other (unless
  // --ior says which).
  if (!options.ior)
    for (const ProfileData& d : data)
      if (d.eta && eta && std::abs(*d.eta - *eta) > 1e-6) {
        std::ostringstream m;
        m << d.source << ": relative index " << *d.eta << ", but " << data.front().source
          << " says " << *eta << ": inputs fitted jointly are one material (give --ior)";
        throw Error(m.str());
      }
  if (!eta && !options.fit_ior) {
    throw Error(
        "--ior: the relative index of refraction is required (the data does not carry one); "
        "or use --fit-ior");
  }
  const double eta0 = eta.value_or(1.4);
  bool any_relative = false;
  for (const ProfileData& d : data) any_relative |= !d.calibrated;
  const bool relative = options.relative.value_or(any_relative);
  if (!relative && any_relative) {
    throw Error(
        "--relative: an input profile is uncalibrated (relative values); its scale must be fitted");
  }
  std::array<bool, 3> channels{false, false, false};
  for (const ProfileData& d : data) {
    for (int c = 0; c < 3; ++c) channels[c] = channels[c] || d.channels[c];
  }
  if (!channels[0] && !channels[1] && !channels[2])
    throw Error(data.front().source +
                ": no channel holds data (every standard error is 0): "
                "nothing to fit");

  FitResult result;
  std::array<StartValues, 3> start;
  std::array<StartValues, 3> given;
  for (int c = 0; c < 3; ++c) {
    if (!channels[c]) continue;
    start[c] = start_values(data.front(), c, eta0, relative, false);
    // A transport mean free path beyond a quarter of the data's reach means the far-field estimate
    // failed (no exponential tail in the image): search instead, since the exclusion radius comes
    // from it too.
    const double reach = data.front().radial.size() ? data.front().radial.r_mm.back() : 0.0;
    if (1.0 / (start[c].sigma_a + start[c].sigma_s_reduced) > 0.25 * reach) {
      start[c] = start_values(data.front(), c, eta0, relative, true);
    }
    given[c] = start[c];
    if (options.start) {
      given[c].sigma_a = (*options.start)[c][0];
      given[c].sigma_s_reduced = (*options.start)[c][1];
    }
  }
  // The tabulated model applies to radial profiles at normal incidence and normal view.
  // At oblique incidence (2D samples, camera along the normal) it corrects the directional dipole.
  bool radial_normal = true, oblique = false;
  for (const ProfileData& d : data) {
    const bool two_d = d.samples_2d.has_value() && d.incidence_polar_deg > 0;
    oblique = oblique || two_d;
    if ((d.incidence_polar_deg > 0.5 && !two_d) || (!d.exitance && d.view_deg > 0.5))
      radial_normal = false;
  }
  std::shared_ptr<const materials::TabulatedProfile> full, fixed;
  std::string table_problem;
  if (radial_normal) {
    try {
      const materials::TransportTable& file =
          options.table ? *options.table : materials::default_transport_table();
      full = materials::cached_tabulated_profile(file, options.g);
      if (!options.fit_ior) {
        if (eta0 < full->eta_min() - 1e-9 || eta0 > full->eta_max() + 1e-9) {
          std::ostringstream m;
          m << "the relative index " << eta0 << " is outside the transport table's range "
            << full->eta_min() << ".." << full->eta_max()
            << " (build a wider table with lucent tabulate)";
          table_problem = m.str();
        } else {
          fixed = materials::cached_tabulated_profile(file, options.g, eta0);
        }
      }
    } catch (const Error& e) {
      // --g only means something to the tabulated model: a g the table lacks is an error, not a
      // quiet fall-back to the dipoles.
      if (std::string(e.what()).rfind("--g", 0) == 0) throw;
      table_problem = e.what();
    }
  } else {
    table_problem =
        "the tabulated model needs a camera along the normal, and oblique incidence as 2D samples";
  }
  // Oblique 2D data at one incidence, eta held: the oblique table's slice, when it has one.
  std::string oblique_source;
  if (oblique && fixed && !options.fit_ior) {
    std::optional<double> incidence;
    bool one_incidence = true;
    for (const ProfileData& d : data) {
      if (!(d.samples_2d.has_value() && d.incidence_polar_deg > 0)) continue;
      if (incidence && std::abs(*incidence - d.incidence_polar_deg) > 1e-6) one_incidence = false;
      incidence = d.incidence_polar_deg;
    }
    if (incidence && one_incidence && options.oblique_table &&
        materials::ObliqueProfile::has_slice(*options.oblique_table, eta0, options.g, *incidence)) {
      auto slice = std::make_shared<const materials::ObliqueProfile>(*options.oblique_table, eta0,
                                                                     options.g, *incidence);
      fixed = std::make_shared<const materials::TabulatedProfile>(fixed->with_oblique(slice));
      oblique_source = slice->to_string();
    }
  }
  if (slab && table_problem.empty()) {
    // The slab's nodes at this (eta, g), the lit side's ending with this table's semi-infinite
    // profile at 4 times the thickest slab.
    for (const ProfileData& d : data)
      if (d.samples_2d.has_value() && d.incidence_polar_deg > 0)
        throw Error(d.source + ": a slab (--thickness-mm) is fitted from radial profiles at normal "
                               "incidence");
    if (!options.slab || options.slab->reflected.empty())
      throw Error("--thickness-mm: the slab's transport tables are missing (lucent fit builds "
                  "them; in the library pass FitOptions::slab)");
    for (const auto* list : {&options.slab->reflected, &options.slab->transmitted})
      for (const materials::TabulatedProfile& node : *list)
        if (std::abs(node.eta_nodes().front() - eta0) > 1e-9 || std::abs(node.g() - options.g) > 1e-9)
          throw Error("--thickness-mm: the slab's tables are for another eta or g than the fit's");
    auto nodes = std::make_shared<materials::SlabNodes>(*options.slab);
    nodes->reflected.push_back(*fixed);
    nodes->log_thickness_s.push_back(nodes->log_thickness_s.back() + std::log(4.0));
    fixed = std::make_shared<const materials::TabulatedProfile>(fixed->with_slab(nodes));
  }
  const bool tab_ok = full && table_problem.empty();
  if (slab && !tab_ok) throw Error("--thickness-mm: " + table_problem);
  if (options.model == FitModel::kTabulated && !tab_ok)
    throw Error("--model tabulated: " + table_problem);
  const materials::TabulatedProfile* tab = options.fit_ior ? full.get() : fixed.get();
  result.g = options.g;
  if (tab_ok) result.table = options.fit_ior ? full : fixed;

  // Each channel's exclusion radius from its own data.
  double pixel_mm = 0;
  for (const ProfileData& d : data) pixel_mm = std::max(pixel_mm, d.radial.pixel_mm);
  const auto exclusion = [&](FitModel m, const std::array<StartValues, 3>& st) {
    std::array<double, 3> e{};
    for (int c = 0; c < 3; ++c) {
      const double mfp = 1.0 / (st[c].sigma_a + st[c].sigma_s_reduced);
      e[c] =
          options.exclude_radius_mm ? *options.exclude_radius_mm
          // 0.1 mean free path, but never past 4 pixels: the start values' mean free path can
          // be far off (a near-black channel at 60 degrees had 32 mm, and at 2.5 mm its fit
          // lost the near field it needs), and the model is exact close in.
          : m == FitModel::kTabulated
              ? std::max(2 * pixel_mm, pixel_mm > 0 ? std::min(0.1 * mfp, 4 * pixel_mm) : 0.1 * mfp)
              : mfp;
    }
    return e;
  };
  int below_noise = 0;
  const auto fit_model = [&](FitModel m, const std::array<StartValues, 3>& first) {
    const materials::TabulatedProfile* t = m == FitModel::kTabulated ? tab : nullptr;
    const std::array<double, 3> ex = exclusion(m, start);
    below_noise = 0;
    ModelFit best = solve(data, options, m, t, eta0, relative, ex, first, channels, &below_noise);
    if (options.start) {
      // Given start values too; keep whichever start reaches the lower cost (a second start is the
      // cheap guard against the shallow valleys of low-albedo profiles).
      ModelFit other =
          solve(data, options, m, t, eta0, relative, ex, given, channels, &below_noise);
      if (other.chi2 <= best.chi2) best = other;
    }
    bool poor = !best.converged;
    for (int c = 0; c < 3; ++c) poor = poor || (channels[c] && best.channels[c].residual_rms > 3.0);
    if (poor) {
      // The far-field start can miss the valley (a profile that ends within a diffusion length has
      // no exponential tail and leaves light outside the image); search a grid of (alpha',
      // sigma_t') for a second start and keep the better solution.
      std::array<StartValues, 3> searched = start;
      for (int c = 0; c < 3; ++c) {
        if (channels[c]) searched[c] = start_values(data.front(), c, eta0, relative, true);
      }
      ModelFit other =
          solve(data, options, m, t, eta0, relative, ex, searched, channels, &below_noise);
      if (other.chi2 < best.chi2) best = other;
    }
    poor = !best.converged;
    for (int c = 0; c < 3; ++c) poor = poor || (channels[c] && best.channels[c].residual_rms > 3.0);
    if (poor && m == FitModel::kTabulated) {
      // Still lost (its start came from a dipole fit that failed, e.g. a dipole valley far from
      // the truth): starts spread over alpha' at the data's far-field sigma_tr, the best of them
      // chosen per channel (the channels' costs are independent), then one solve from there.
      std::array<StartValues, 3> composite = start;
      std::array<double, 3> best_rms{INFINITY, INFINITY, INFINITY};
      for (double a : {0.3, 0.6, 0.8, 0.9, 0.95, 0.98, 0.995, 0.999}) {
        std::array<StartValues, 3> st = start;
        for (int c = 0; c < 3; ++c) {
          if (!channels[c]) continue;
          const double sa = start[c].sigma_a, ss = start[c].sigma_s_reduced;
          const double sigma_tr = std::sqrt(3 * sa * (sa + ss));
          const double st_reduced = sigma_tr / std::sqrt(3 * (1 - a));
          st[c].sigma_a = (1 - a) * st_reduced;
          st[c].sigma_s_reduced = a * st_reduced;
        }
        const ModelFit f =
            solve(data, options, m, t, eta0, relative, ex, st, channels, &below_noise);
        for (int c = 0; c < 3; ++c) {
          if (channels[c] && f.channels[c].residual_rms < best_rms[c]) {
            best_rms[c] = f.channels[c].residual_rms;
            composite[c].sigma_a = f.channels[c].sigma_a;
            composite[c].sigma_s_reduced = f.channels[c].sigma_s_reduced;
          }
        }
      }
      ModelFit other =
          solve(data, options, m, t, eta0, relative, ex, composite, channels, &below_noise);
      if (other.chi2 < best.chi2) best = other;
    }
    return best;
  };
  const auto started_from = [&](const ModelFit& f) {
    std::array<StartValues, 3> st = start;
    for (int c = 0; c < 3; ++c) {
      if (!channels[c]) continue;
      st[c].sigma_a = f.channels[c].sigma_a;
      st[c].sigma_s_reduced = f.channels[c].sigma_s_reduced;
      st[c].log_scale = std::log(f.scale);
    }
    return st;
  };

  if (tab_ok && !options.systematics) {
    // The one model asked for and nothing else (timing); a tabulated fit starts from the data.
    const FitModel m = options.model == FitModel::kAuto ? FitModel::kTabulated : options.model;
    result.candidates.push_back(fit_model(m, start));
  } else if (tab_ok && options.model != FitModel::kDirectionalDipole) {
    // The accurate model, started from the standard dipole's solution (cheap, and in the valley).
    // A dipole that cannot be fitted at all (its exclusion of one mean free path leaves a
    // near-black channel nothing) is no reason to fail the accurate fit: in auto mode it is left
    // out, with a note, and the tabulated fit starts from the data.
    std::optional<ModelFit> dipole;
    std::string dipole_problem;
    try {
      report("fitting the standard dipole", 0.0);
      dipole = fit_model(FitModel::kDipole, start);
    } catch (const Error& e) {
      if (options.model == FitModel::kDipole) throw;
      dipole_problem = e.what();
    }
    report("fitting the tabulated model", kShareTabulated);
    ModelFit accurate = fit_model(FitModel::kTabulated, dipole ? started_from(*dipole) : start);
    result.candidates.push_back(accurate);
    // A slab: the (semi-infinite) dipoles only start the accurate fit.
    if (dipole && options.model != FitModel::kTabulated && !slab)
      result.candidates.push_back(*dipole);
    if (options.model == FitModel::kAuto && !slab) {
      try {
        report("fitting the directional dipole", kShareDirectional);
        result.candidates.push_back(fit_model(FitModel::kDirectionalDipole, start));
      } catch (const Error& e) {
        if (dipole_problem.empty()) dipole_problem = e.what();
      }
    }
    if (!dipole_problem.empty())
      result.notes.push_back("the diffusion models could not be fitted to these data (" +
                             dipole_problem + "); only the tabulated model was");
    if (options.model == FitModel::kDipole) std::swap(result.candidates[0], result.candidates[1]);
  } else if (tab_ok) {  // ddipole requested: the tabulated fit gives its systematic
    result.candidates.push_back(fit_model(FitModel::kDirectionalDipole, start));
    result.candidates.push_back(
        fit_model(FitModel::kTabulated, started_from(result.candidates[0])));
  } else if (options.model == FitModel::kAuto) {
    result.candidates.push_back(fit_model(FitModel::kDipole, start));
    result.candidates.push_back(fit_model(FitModel::kDirectionalDipole, start));
  } else {
    result.candidates.push_back(fit_model(options.model, start));
  }
  if (below_noise > 0) {
    result.notes.push_back(std::to_string(below_noise) +
                           " samples below the noise floor (value < 2 standard errors, or past "
                           "the point where the profile sinks into the noise) left out");
  }
  for (const ProfileData& d : data)
    result.notes.insert(result.notes.end(), d.notes.begin(), d.notes.end());

  if (tab_ok) {
    result.chosen = result.candidates.front();
    if (options.model == FitModel::kAuto && oblique && !oblique_source.empty()) {
      result.reason =
          "tabulated: oblique incidence, exact to radiative transfer (lucent's Monte Carlo 2D "
          "transport table at the capture's incidence, " +
          oblique_source + "); the cheaper models are judged against it";
    } else if (options.model == FitModel::kAuto && oblique) {
      result.reason =
          "tabulated: oblique incidence, the directional dipole corrected by lucent's Monte Carlo "
          "transport table (g = " +
          g_text(options.g) +
          ") to transport at normal incidence; the cheaper models are judged against it";
    } else if (slab) {
      std::ostringstream why;
      why << "tabulated: exact to radiative transfer for a slab of "
          << [&] {
               for (const ProfileData& d : data)
                 if (d.thickness_mm) return *d.thickness_mm;
               return 0.0;
             }()
          << " mm under a normal pencil beam (lucent's Monte Carlo slab tables at g = "
          << g_text(options.g) << "); the diffusion models, of a semi-infinite sample, are not "
          << "judged";
      result.reason = why.str();
    } else if (options.model == FitModel::kAuto) {
      result.reason =
          "tabulated: exact to radiative transfer for a radial profile at normal incidence "
          "(lucent's Monte Carlo transport table at g = " +
          g_text(options.g) + "); the cheaper models are judged against it";
    } else {
      result.reason = "model " + model_name(result.chosen.model) + " requested";
    }
  } else if (result.candidates.size() == 1) {
    result.chosen = result.candidates.front();
    result.reason = "model " + model_name(result.chosen.model) + " requested";
  } else {
    // No accurate model for these data: the simplest diffusion model the data does not reject,
    // the standard dipole unless the directional one fits markedly better (AIC lower by more than
    // 10, i.e. the dipole is e^5 = 150 times less likely).
    const ModelFit& dipole = result.candidates[0];
    const ModelFit& ddipole = result.candidates[1];
    std::ostringstream why;
    why.precision(4);
    if (ddipole.aic < dipole.aic - 10) {
      result.chosen = ddipole;
      why << "ddipole: its AIC " << ddipole.aic << " is lower than the dipole's " << dipole.aic
          << " by more than 10, so the data rejects the simpler standard dipole";
    } else {
      result.chosen = dipole;
      why << "dipole: the simpler model is not rejected (AIC " << dipole.aic << " vs ddipole "
          << ddipole.aic << ")";
    }
    why << "; no accurate model: " << table_problem;
    result.reason = why.str();
    result.notes.push_back("no model exact to transport for these data (" + table_problem + ")");
  }
  if (tab_ok && options.systematics && result.chosen.model == FitModel::kTabulated) {
    report("the table's systematic (bootstrap and accuracy refits)", kShareTableSystematic);
    // The tabulated model's own error, two parts in quadrature. (1) The table's Monte Carlo noise,
    // propagated by a parametric bootstrap: refits against realisations of the table drawn
    // within its stated per-entry standard errors (common to every bin, so the weights alone
    // cannot carry it). (2) Its accuracy as measured against fresh Monte Carlo runs
    // (tests/acquire/tabulate_test.cpp: profiles within kTableAccuracy), as the shift of the
    // answer under a smooth relative change of the model of that size, tilted or bowed across
    // log rho.
    constexpr int kBootstrap = 8;
    constexpr double kTableAccuracy = 0.01;
    const std::array<StartValues, 3> st = started_from(result.chosen);
    const std::array<double, 3> ex = exclusion(FitModel::kTabulated, st);
    std::array<std::array<double, 4>, 3> moments{};  // sum a, sum a^2, sum s, sum s^2
    std::array<std::array<double, 2>, 3> shift2{};   // squared shifts under the model changes
    int ignored = 0;
    for (int b = 0; b < kBootstrap; ++b) {
      const materials::TabulatedProfile shaken = tab->perturbed(1000 + std::uint64_t(b));
      const ModelFit f = solve(data, options, FitModel::kTabulated, &shaken, result.chosen.eta,
                               relative, ex, st, channels, &ignored);
      for (int c = 0; c < 3; ++c) {
        const double a = f.channels[c].sigma_a, s = f.channels[c].sigma_s_reduced;
        moments[c][0] += a, moments[c][1] += a * a, moments[c][2] += s, moments[c][3] += s * s;
      }
    }
    for (int shape : {1, 2}) {
      const ModelFit f =
          solve(data, options, FitModel::kTabulated, tab, result.chosen.eta, relative, ex, st,
                channels, &ignored, ModelPerturbation{kTableAccuracy, shape});
      for (int c = 0; c < 3; ++c) {
        shift2[c][0] += std::pow(f.channels[c].sigma_a - result.chosen.channels[c].sigma_a, 2);
        shift2[c][1] +=
            std::pow(f.channels[c].sigma_s_reduced - result.chosen.channels[c].sigma_s_reduced, 2);
      }
    }
    // A sigma_a the data cannot see (below what their reach shows, sigma_tr R < 1) may sit near 0
    // while the truth is anywhere up to that bound; sigma_s' moves with it. Refit with sigma_a held
    // at the bound: the move of sigma_s' joins its systematic.
    std::array<double, 3> held{};
    bool any_held = false;
    for (int c = 0; c < 3; ++c) {
      const ChannelFit& ch = result.chosen.channels[c];
      const double R = ch.range_end_mm, st_reduced = ch.sigma_a + ch.sigma_s_reduced;
      if (!channels[c] || !(R > 0)) continue;
      const double bound = 1.0 / (3 * st_reduced * R * R);
      if (ch.sigma_a < 0.5 * bound) held[c] = bound, any_held = true;
    }
    if (any_held) {
      const ModelFit f = solve(data, options, FitModel::kTabulated, tab, result.chosen.eta,
                               relative, ex, st, channels, &ignored, ModelPerturbation{}, &held);
      for (int c = 0; c < 3; ++c)
        if (held[c] > 0)
          shift2[c][1] += std::pow(
              f.channels[c].sigma_s_reduced - result.chosen.channels[c].sigma_s_reduced, 2);
    }
    const auto var = [&](double sum, double sum2) {
      return std::max(0.0, (sum2 - sum * sum / kBootstrap) / (kBootstrap - 1));
    };
    for (ModelFit* f : {&result.chosen, &result.candidates.front()}) {
      for (int c = 0; c < 3; ++c) {
        if (!channels[c]) continue;
        f->channels[c].sd_sys_sigma_a = std::sqrt(var(moments[c][0], moments[c][1]) + shift2[c][0]);
        f->channels[c].sd_sys_sigma_s_reduced =
            std::sqrt(var(moments[c][2], moments[c][3]) + shift2[c][1]);
      }
    }
  }
  detail::finish_uncertainty(result, options, channels);
  // A slab beyond the thickness nodes is clamped to the nearest: said, with the numbers.
  if (slab && options.slab) {
    const auto& lit = options.slab->log_thickness_s;
    const auto& far = options.slab->log_thickness_s_transmitted;
    for (const ProfileData& d : data) {
      if (!d.thickness_mm) continue;
      const std::vector<double>& x = d.transmitted ? far : lit;
      if (x.empty()) continue;
      for (int c = 0; c < 3; ++c) {
        if (!channels[c] || !d.channels[c]) continue;
        const double t = *d.thickness_mm * result.chosen.channels[c].sigma_s_reduced;
        if (t >= std::exp(x.front()) * 0.999 && (!d.transmitted || t <= std::exp(x.back()) * 1.001))
          continue;
        std::ostringstream w;
        w.precision(3);
        w << d.source << ": channel " << "RGB"[c] << ": the slab is " << t
          << " reduced scattering lengths thick (d sigma_s'), outside the slab tables' "
          << std::exp(x.front()) << ".." << std::exp(x.back())
          << "; the model there is the nearest table's: distrust this channel";
        result.warnings.push_back(w.str());
      }
    }
  }
  if (slab && options.systematics)
    result.notes.push_back(
        "a slab: no cheaper model is judged (the dipoles are of a semi-infinite sample), and the "
        "g systematic is not computed (the slab's tables hold one g)");
  if (tab_ok && options.systematics && result.chosen.model == FitModel::kTabulated && !slab) {
    report("the adequacy of the dipoles and the g systematic", kShareAdequacy);
    detail::judge_adequacy(result, data, channels);
    // g: radial data cannot tell it from sigma_s; say how far the answer moves at the other end.
    const double g_other = options.g < 0.45 ? 0.9 : 0.0;
    try {
      // The table in use, or the shipped one when it has no slice at g_other (a slice built for
      // this fit's g holds that g alone).
      const std::optional<double> eta_held =
          options.fit_ior ? std::nullopt : std::optional<double>(result.chosen.eta);
      std::shared_ptr<const materials::TabulatedProfile> other_profile;
      try {
        other_profile = materials::cached_tabulated_profile(
            options.table ? *options.table : materials::default_transport_table(), g_other,
            eta_held);
      } catch (const Error&) {
        // Only for a slice built for this g (one g in the table); a table the user gave stands.
        bool one_g = options.table != nullptr;
        if (one_g)
          for (const materials::TransportTableSlice& s : options.table->slices)
            one_g = one_g && s.g == options.table->slices.front().g;
        if (!one_g) throw;
        other_profile = materials::cached_tabulated_profile(materials::default_transport_table(),
                                                            g_other, eta_held);
      }
      const materials::TabulatedProfile& other = *other_profile;
      const std::array<StartValues, 3> st = started_from(result.chosen);
      int ignored = 0;
      const ModelFit shifted =
          solve(data, options, FitModel::kTabulated, &other, result.chosen.eta, relative,
                exclusion(FitModel::kTabulated, st), st, channels, &ignored);
      for (int c = 0; c < 3; ++c)
        result.g_09.push_back({shifted.channels[c].sigma_a, shifted.channels[c].sigma_s_reduced});
      result.g_other = g_other;
    } catch (const Error&) {
      // A table without that g: nothing to say.
    }
  }
  // What each input's system response did (convolved with what, or a pencil beam assumed).
  for (const ProfileData& d : data)
    result.notes.push_back(detail::describe_system_response(d, options.beam_sigma_mm));
  // A semi-infinite answer holds for samples thick enough: the thinnest slab whose profile stays
  // within 10% of it over the data (diffusion theory). A slab thinner than that but thick enough
  // to leave no structure the fit can see would pass for a semi-infinite sample of higher sigma_a
  // (an 8 mm chicken slab fitted untold: sigma_a +35%), so the assumption is said.
  if (!slab) {
    double thinnest = 0;
    for (int c = 0; c < 3; ++c) {
      const ChannelFit& ch = result.chosen.channels[c];
      if (!channels[c] || !(ch.range_end_mm > 0)) continue;
      thinnest = std::max(thinnest, detail::thinnest_semi_infinite_mm(
                                        ch.sigma_a, ch.sigma_s_reduced, result.chosen.eta,
                                        ch.range_end_mm, 0.1));
    }
    result.assumed_thickness_mm = thinnest;
    if (thinnest > 0) {
      std::ostringstream note;
      note.precision(3);
      note << "this answer assumes a semi-infinite sample, i.e. one thicker than about "
           << thinnest
           << " mm (a thinner slab changes the profile by more than 10% within the data's "
              "reach and passes for higher absorption): if it is a thinner slab, give "
              "--thickness-mm";
      result.notes.push_back(note.str());
    }
  }
  result.exclude_radius_mm = INFINITY;
  for (int c = 0; c < 3; ++c)
    if (channels[c])
      result.exclude_radius_mm =
          std::min(result.exclude_radius_mm, result.chosen.channels[c].exclude_radius_mm);
  for (int c = 0; c < 3; ++c) {
    const double s = result.chosen.calibration_scale[c];
    const double se = data.front().calibration_relative_se[c];
    if (se > 0 && std::abs(std::log(s)) > 3 * se) {
      std::ostringstream note;
      note.precision(3);
      note << "channel " << kChannelNames[c]
           << ": the model reaches the data only with the calibration scaled by " << s
           << " (its uncertainty is " << 100 * se
           << "%): model and data disagree in absolute level";
      result.notes.push_back(note.str());
    }
  }
  if (!result.chosen.undetermined.empty()) {
    for (const std::string& u : result.chosen.undetermined) {
      result.notes.push_back("the data cannot determine " + u + " (left out of the uncertainty)");
    }
  }
  if (!result.chosen.converged && !options.allow_unconverged) {
    std::ostringstream s;
    s.precision(6);
    s << "fit did not converge (" << result.chosen.message << "); best values:";
    for (int c = 0; c < 3; ++c) {
      s << " " << kChannelNames[c] << " sigma_a=" << result.chosen.channels[c].sigma_a
        << " sigma_s'=" << result.chosen.channels[c].sigma_s_reduced;
    }
    s << " (use --allow-unconverged to keep them)";
    throw Error(s.str());
  }
  return result;
}

}  // namespace lucent::fit
