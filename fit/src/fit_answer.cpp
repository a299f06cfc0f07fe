// The stages of a fit that judge its answer (profile_fit.h): the model chosen and why, the
// tabulated model's own systematic, a slab outside its tables, the cheaper models' adequacy and the
// g systematic, and what the answer assumes.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "fit_uncertainty.h"
#include "lack_of_fit.h"
#include "lucent/core/error.h"
#include "lucent/materials/transport_table.h"
#include "profile_fit.h"
#include "system_response.h"

namespace lucent::fit::detail {
namespace {

std::string model_name(FitModel m) { return to_string(m); }

std::string g_text(double g) {  // 0.917, not std::to_string's 0.917000 cut to 0.91
  std::ostringstream s;
  s << g;
  return s.str();
}

}  // namespace

// The chosen model and the reason for it, in words.
void ProfileFit::choose_model() {
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
}

// The tabulated model's own systematic: the table's noise by bootstrap, its accuracy by refits.
void ProfileFit::table_systematic() {
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
  // The bootstrap and accuracy refits start at the answer and move from it by a fraction of its
  // SD, so 3 solver steps reach their solution (the bootstrap's own sampling error
  // with 8 draws is ~25%): capped (FitOptions::systematic_refit_iterations), they no longer crawl
  // to the full tolerances, which made most of a tabulated 2D fit's time (issue 37).
  FitOptions refit_options = options;
  if (const int cap = options.systematic_refit_iterations; cap > 0)
    refit_options.max_iterations =
        options.max_iterations > 0 ? std::min(options.max_iterations, cap) : cap;
  const std::array<StartValues, 3> st = started_from(result.chosen);
  const std::array<double, 3> ex = exclusion(FitModel::kTabulated, st);
  std::array<std::array<double, 4>, 3> moments{};  // sum a, sum a^2, sum s, sum s^2
  std::array<std::array<double, 2>, 3> shift2{};   // squared shifts under the model changes
  int ignored = 0;
  for (int b = 0; b < kBootstrap; ++b) {
    const materials::TabulatedProfile shaken = tab->perturbed(1000 + std::uint64_t(b));
    const ModelFit f = solve(data, refit_options, FitModel::kTabulated, &shaken, result.chosen.eta,
                             relative, ex, st, channels, &ignored);
    for (int c = 0; c < 3; ++c) {
      const double a = f.channels[c].sigma_a, s = f.channels[c].sigma_s_reduced;
      moments[c][0] += a, moments[c][1] += a * a, moments[c][2] += s, moments[c][3] += s * s;
    }
  }
  for (int shape : {1, 2}) {
    const ModelFit f =
        solve(data, refit_options, FitModel::kTabulated, tab, result.chosen.eta, relative, ex, st,
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

// A slab beyond the thickness nodes is clamped to the nearest: said, with the numbers.
void ProfileFit::check_slab_range() {
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
}

// How far the cheaper models are from the accurate one, and where g = 0 / 0.9 would move it.
void ProfileFit::judge_cheaper_models_and_g() {
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
}

// What the answer assumes (system response, semi-infinite sample), what the data cannot
// determine, and convergence.
void ProfileFit::state_assumptions() {
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
}

}  // namespace lucent::fit::detail
