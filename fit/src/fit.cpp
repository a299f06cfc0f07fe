// fit_profiles: the public entry, and the stages of a fit that fit (profile_fit.h): the inputs
// read, the start values, the tabulated model's table, the candidate models with their restarts.
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
#include "lucent/core/error.h"
#include "lucent/materials/tabulated.h"
#include "lucent/materials/transport_table.h"
#include "lucent/version.h"
#include "model_prediction.h"
#include "profile_fit.h"
#include "system_response.h"

namespace lucent::fit {
namespace detail {

// The inputs: slab thicknesses, finite values, one relative index, calibration, channels.
void ProfileFit::check_inputs() {
  // A slab: the thickness the options give every input, or each input's own.
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
  eta0 = eta.value_or(1.4);
  bool any_relative = false;
  for (const ProfileData& d : data) any_relative |= !d.calibrated;
  relative = options.relative.value_or(any_relative);
  if (!relative && any_relative) {
    throw Error(
        "--relative: an input profile is uncalibrated (relative values); its scale must be fitted");
  }
  for (const ProfileData& d : data) {
    for (int c = 0; c < 3; ++c) channels[c] = channels[c] || d.channels[c];
  }
  if (!channels[0] && !channels[1] && !channels[2])
    throw Error(data.front().source +
                ": no channel holds data (every standard error is 0): "
                "nothing to fit");
}

// Start values per channel from the data (and the options' own).
void ProfileFit::choose_starts() {
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
}

// The tabulated model's table for these data (radial, oblique or slab), or why none applies.
void ProfileFit::choose_table() {
  // The tabulated model applies to radial profiles at normal incidence and normal view.
  // At oblique incidence (2D samples, camera along the normal) it corrects the directional dipole.
  bool radial_normal = true;
  for (const ProfileData& d : data) {
    const bool two_d = d.samples_2d.has_value() && d.incidence_polar_deg > 0;
    oblique = oblique || two_d;
    if ((d.incidence_polar_deg > 0.5 && !two_d) || (!d.exitance && d.view_deg > 0.5))
      radial_normal = false;
  }
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
  tab_ok = full && table_problem.empty();
  if (slab && !tab_ok) throw Error("--thickness-mm: " + table_problem);
  if (options.model == FitModel::kTabulated && !tab_ok)
    throw Error("--model tabulated: " + table_problem);
  tab = options.fit_ior ? full.get() : fixed.get();
  result.g = options.g;
  if (tab_ok) result.table = options.fit_ior ? full : fixed;
  for (const ProfileData& d : data) pixel_mm = std::max(pixel_mm, d.radial.pixel_mm);
}

// Each channel's exclusion radius from its own data.
std::array<double, 3> ProfileFit::exclusion(FitModel m,
                                            const std::array<StartValues, 3>& st) const {
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
}

// One model fitted, with the restarts that guard against the valleys a start can miss.
ModelFit ProfileFit::fit_model(FitModel m, const std::array<StartValues, 3>& first) {
  const materials::TabulatedProfile* t = m == FitModel::kTabulated ? tab : nullptr;
  const std::array<double, 3> ex = exclusion(m, start);
  below_noise = 0;
  ModelFit best = solve(data, options, m, t, eta0, relative, ex, first, channels, &below_noise);
  if (options.start) {
    // Given start values too; keep whichever start reaches the lower cost (a second start is the
    // cheap guard against the shallow valleys of low-albedo profiles).
    ModelFit other = solve(data, options, m, t, eta0, relative, ex, given, channels, &below_noise);
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
      const ModelFit f = solve(data, options, m, t, eta0, relative, ex, st, channels, &below_noise);
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
}

// Start values at a fit's solution.
std::array<StartValues, 3> ProfileFit::started_from(const ModelFit& f) const {
  std::array<StartValues, 3> st = start;
  for (int c = 0; c < 3; ++c) {
    if (!channels[c]) continue;
    st[c].sigma_a = f.channels[c].sigma_a;
    st[c].sigma_s_reduced = f.channels[c].sigma_s_reduced;
    st[c].log_scale = std::log(f.scale);
  }
  return st;
}

// The candidate models: the accurate one and the cheaper ones it judges (or the one asked for).
void ProfileFit::fit_candidates() {
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
}

}  // namespace detail

FitResult fit_profiles(const std::vector<ProfileData>& input, const FitOptions& options) {
  if (options.fit_thickness) return detail::fit_unknown_thickness(input, options);
  return detail::ProfileFit(input, options).run();
}

}  // namespace lucent::fit
