// Total uncertainty, warnings and model adequacy (fit_uncertainty.h).
#include "fit_uncertainty.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "lucent/core/error.h"
#include "model_prediction.h"

namespace lucent::fit {

FitModel parse_fit_model(const std::string& name, const std::string& option) {
  if (name == "auto") return FitModel::kAuto;
  if (name == "tabulated") return FitModel::kTabulated;
  if (name == "dipole") return FitModel::kDipole;
  if (name == "ddipole") return FitModel::kDirectionalDipole;
  throw Error(option + ": expected auto, tabulated, dipole or ddipole, got '" + name + "'");
}

Quality parse_quality(const std::string& name, const std::string& option) {
  if (name == "fast") return Quality::kFast;
  if (name == "balanced") return Quality::kBalanced;
  if (name == "accurate") return Quality::kAccurate;
  throw Error(option + ": expected fast, balanced or accurate, got '" + name + "'");
}

std::string to_string(FitModel m) {
  switch (m) {
    case FitModel::kDipole: return "dipole";
    case FitModel::kDirectionalDipole: return "ddipole";
    case FitModel::kTabulated: return "tabulated";
    case FitModel::kAuto: return "auto";
  }
  return "auto";
}

namespace detail {
namespace {

const char* kNames[3] = {"R", "G", "B"};

std::string number(double v, int precision = 3) {
  std::ostringstream s;
  s.precision(precision);
  s << v;
  return s.str();
}

}  // namespace

void finish_uncertainty(FitResult& result, const FitOptions& options,
                        const std::array<bool, 3>& channels) {
  const ModelFit* accurate = nullptr;
  for (const ModelFit& f : result.candidates)
    if (f.model == FitModel::kTabulated) accurate = &f;
  const ModelFit reference = accurate ? *accurate : ModelFit{};
  const auto finish = [&](ModelFit& f) {
    for (int c = 0; c < 3; ++c) {
      ChannelFit& ch = f.channels[c];
      // The tabulated fit's systematic (its table's Monte Carlo error) was set by the bootstrap.
      if (accurate && f.model != FitModel::kTabulated) {
        ch.sd_sys_sigma_a = std::abs(ch.sigma_a - reference.channels[c].sigma_a);
        ch.sd_sys_sigma_s_reduced =
            std::abs(ch.sigma_s_reduced - reference.channels[c].sigma_s_reduced);
      }
      ch.sd_sigma_a = std::hypot(ch.sd_stat_sigma_a, ch.sd_sys_sigma_a);
      ch.sd_sigma_s_reduced = std::hypot(ch.sd_stat_sigma_s_reduced, ch.sd_sys_sigma_s_reduced);
    }
  };
  for (ModelFit& f : result.candidates) finish(f);
  finish(result.chosen);
  if (!accurate && result.candidates.size() == 2) {
    // No model exact to transport for these data (oblique 2D, or eta outside the table): the two
    // diffusion models' disagreement is the only measure of their error there is, and it is
    // carried as the systematic rather than pretending the chosen model is exact.
    const ModelFit& other = result.candidates[0].model == result.chosen.model
                                ? result.candidates[1]
                                : result.candidates[0];
    for (int c = 0; c < 3; ++c) {
      ChannelFit& ch = result.chosen.channels[c];
      ch.sd_sys_sigma_a = std::abs(ch.sigma_a - other.channels[c].sigma_a);
      ch.sd_sys_sigma_s_reduced = std::abs(ch.sigma_s_reduced - other.channels[c].sigma_s_reduced);
      ch.sd_sigma_a = std::hypot(ch.sd_stat_sigma_a, ch.sd_sys_sigma_a);
      ch.sd_sigma_s_reduced = std::hypot(ch.sd_stat_sigma_s_reduced, ch.sd_sys_sigma_s_reduced);
    }
    result.notes.push_back(
        "systematic: the disagreement of the standard and directional dipoles on these data "
        "(no model exact to transport applies), so the total SD is wide where they differ");
  }

  const ModelFit& f = result.chosen;
  for (int c = 0; c < 3; ++c) {
    if (!channels[c]) continue;
    const ChannelFit& ch = f.channels[c];
    if (ch.range_diffusion_lengths < 3) {
      const double sigma_tr = std::sqrt(3 * ch.sigma_a * (ch.sigma_a + ch.sigma_s_reduced));
      result.warnings.push_back(
          std::string("channel ") + kNames[c] + ": the usable range " +
          number(ch.exclude_radius_mm) + ".." + number(ch.range_end_mm) + " mm spans only " +
          number(ch.range_diffusion_lengths, 2) + " diffuse mean free paths (1/sigma_tr = " +
          // A sigma_a fitted to 0 has no diffuse mean free path: said in words, never "inf".
          (sigma_tr > 0 ? number(1 / sigma_tr) + " mm" : std::string("unbounded: sigma_a fitted 0")) +
          "; about 3 are needed to separate sigma_a from sigma_s'): distrust this channel, or "
          "image farther out (larger field, longer exposure)");
    }
  }
  if (options.fit_ior) {
    const double lo = f.model == FitModel::kTabulated && result.table ? result.table->eta_min() : 1.0001;
    const double hi = f.model == FitModel::kTabulated && result.table ? result.table->eta_max() : 2.5;
    const bool edge = f.eta < lo + 0.005 || f.eta > hi - 0.005;
    if (edge || !(f.sd_eta < 0.1 * f.eta)) {
      const std::string why = edge ? "runs to the edge of its range " + number(lo) + ".." +
                                         number(hi)
                                   : "has a standard deviation of " + number(f.sd_eta);
      result.warnings.push_back("eta is undetermined: the fitted " + number(f.eta, 4) + " " + why +
                                "; radial profiles barely constrain it. Give --ior instead");
      result.chosen.undetermined.push_back("eta");
      for (ModelFit& candidate : result.candidates)
        if (candidate.model == f.model) candidate.undetermined.push_back("eta");
    }
  }
}

void judge_adequacy(FitResult& result, const std::vector<ProfileData>& data,
                    const std::array<bool, 3>& channels) {
  const ModelFit& f = result.chosen;
  if (!result.table || data.empty()) return;
  const ProfileData& d = data.front();
  CaptureGeometry g;
  g.cos_incidence = std::cos(d.incidence_polar_deg * std::numbers::pi / 180);
  g.cos_view = std::cos(d.view_deg * std::numbers::pi / 180);
  g.exitance = d.exitance;
  g.per_incident_power = d.per_incident_power;
  const GaussLegendre gl = gauss_legendre(1);
  for (FitModel m : {FitModel::kDipole, FitModel::kDirectionalDipole}) {
    // Relative deviation of model m from the table, per channel, at 200 log-spaced radii over
    // the channel's usable range.
    std::vector<std::vector<std::pair<double, double>>> dev(3);
    double reach = 0, max_deviation = 0;
    for (int c = 0; c < 3; ++c) {
      if (!channels[c]) continue;
      const ChannelFit& ch = f.channels[c];
      const materials::Medium<double> medium =
          materials::Medium<double>::from_reduced(ch.sigma_a, ch.sigma_s_reduced, f.eta);
      const double front_m = fresnel_factor(g, f.eta, m);
      const double front_t = fresnel_factor(g, f.eta, FitModel::kTabulated);
      reach = std::max(reach, ch.range_end_mm);
      const double r0 = std::max(ch.exclude_radius_mm, 1e-3), r1 = std::max(ch.range_end_mm, r0);
      for (int k = 0; k <= 200; ++k) {
        const double r = r0 * std::pow(r1 / r0, k / 200.0);
        const double vm = front_m * model_value(m, nullptr, medium, g, true, r, r, r, r, 0, 0, gl);
        const double vt = front_t * model_value(FitModel::kTabulated, result.table.get(), medium,
                                                g, true, r, r, r, r, 0, 0, gl);
        const double d = vt > 0 ? std::abs(vm / vt - 1) : INFINITY;
        dev[std::size_t(c)].emplace_back(r, d);
        max_deviation = std::max(max_deviation, d);
      }
    }
    // The tightest of a few tolerance bands the model keeps beyond some radius within the first
    // half of the data's reach (ModelAdequacy::kBar, 3%, is the bar for "adequate").
    ModelAdequacy a;
    a.model = m;
    a.max_deviation = max_deviation;
    a.beyond_mm = INFINITY;
    for (double tolerance : {ModelAdequacy::kBar, 0.05, 0.1, 0.2, 0.5}) {
      double beyond = 0;
      for (const auto& channel : dev) {
        double last_bad = 0;
        for (const auto& [r, d] : channel)
          if (!(d <= tolerance)) last_bad = r;
        if (!channel.empty() && last_bad >= channel.back().first * 0.999) last_bad = INFINITY;
        beyond = std::max(beyond, last_bad);
      }
      a.tolerance = tolerance;
      a.beyond_mm = beyond;
      if (beyond <= 0.5 * reach) break;
    }
    a.adequate = a.tolerance <= ModelAdequacy::kBar && a.beyond_mm <= 0.5 * reach;
    std::ostringstream note;
    note << to_string(m) << " with these coefficients: ";
    if (a.beyond_mm <= 0.5 * reach) {
      note << "within " << 100 * a.tolerance << "% of the tabulated profile "
           << (a.beyond_mm > 0 ? "beyond " + number(a.beyond_mm) + " mm" : "over all the data")
           << " (worst " << number(100 * a.max_deviation, 2) << "% closer in)"
           << (a.adequate ? "; enough for scenes whose detail is coarser than " +
                                number(std::max(a.beyond_mm, 1e-3)) + " mm"
                          : "; not adequate (the bar is " + number(100 * ModelAdequacy::kBar) +
                                "%)");
    } else {
      note << "more than " << 100 * a.tolerance << "% off the tabulated profile over much of "
           << "the data (worst " << number(100 * a.max_deviation, 2) << "%)";
    }
    result.notes.push_back(note.str());
    result.adequacy.push_back(a);
  }
  // The cheapest adequate model ("none" when none is); the renderers' fallback is that one, or the
  // closest diffusion model (tightest band, then smallest radius) when none is adequate.
  const ModelAdequacy* adequate = nullptr;
  const ModelAdequacy* closest = nullptr;
  for (const ModelAdequacy& a : result.adequacy) {
    if (a.adequate && !adequate) adequate = &a;
    if (!closest || a.tolerance < closest->tolerance ||
        (a.tolerance == closest->tolerance && a.beyond_mm < closest->beyond_mm))
      closest = &a;
  }
  result.adequate_model = adequate ? to_string(adequate->model) : "none";
  const ModelAdequacy* fallback = adequate ? adequate : closest;
  result.fallback_model = fallback ? to_string(fallback->model) : "";
}

}  // namespace detail
}  // namespace lucent::fit
