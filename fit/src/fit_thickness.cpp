// --fit-thickness: a slab's thickness from its profiles, by profile likelihood. Internal to
// lucent_fit.
//
// The thickness is one number shared by every channel and input, and the slab model's dependence
// on it is through the tables' interpolation in ln(d sigma_s') (materials::TabulatedModel), which
// is flat beyond the thickest node: a derivative-based joint solve would stall there. So the
// thickness is searched outside the solver: the coefficients are fitted at each trial thickness
// (each fit ~ a few ms), chi^2 is scanned over a log grid spanning the tables' nodes for every
// channel, the minimum refined by golden section in ln d, and the interval where chi^2 stays
// within max(1, reduced chi^2) of the minimum (the 1 SD profile-likelihood interval, widened by any
// lack of fit) bisected. An interval open above means the data look semi-infinite: the thickness
// is named undetermined, with the thinnest slab they allow. The coefficients' spread over the
// interval joins their systematic.
#include "fit_thickness.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include "lucent/core/error.h"

namespace lucent::fit::detail {
namespace {

constexpr double kMaxThicknessMm = 1e4;

struct Trial {
  double log_d = 0;
  double chi2 = std::numeric_limits<double>::infinity();
  FitResult result;
};

// The coefficient fits at trial thicknesses, counted.
class ThicknessTrials {
 public:
  ThicknessTrials(const std::vector<ProfileData>& data, const FitOptions& options)
      : data_(data), inner_(options) {
    inner_.fit_thickness = false;
    inner_.systematics = false;
    inner_.allow_unconverged = true;
    inner_.progress = {};
  }

  // The fit at thickness exp(log_d) mm.
  Trial operator()(double log_d) {
    Trial t;
    t.log_d = log_d;
    FitOptions o = inner_;
    o.thickness_mm = std::exp(log_d);
    ++fits_;
    try {
      t.result = fit_profiles(data_, o);
      t.chi2 = t.result.chosen.chi2;
    } catch (const Error&) {
      // A thickness the data cannot be fitted at: it is not the minimum.
    }
    return t;
  }

  int fits() const { return fits_; }

 private:
  const std::vector<ProfileData>& data_;
  FitOptions inner_;
  int fits_ = 0;
};

// Stage 1: refuse options a fitted thickness cannot go with.
void check_thickness_options(const FitOptions& options) {
  if (options.thickness_mm)
    throw Error("--fit-thickness: the thickness is either given (--thickness-mm) or fitted, not both");
  if (options.fit_ior)
    throw Error("--fit-thickness: a slab is fitted at a given index (--ior), not with --fit-ior");
  if (options.model == FitModel::kDipole || options.model == FitModel::kDirectionalDipole)
    throw Error("--fit-thickness: the diffusion models are of a semi-infinite sample; a slab is "
                "fitted with the tabulated model");
}

// Stage 2: the largest radius any radial profile reaches, mm; there must be one.
double radial_reach_mm(const std::vector<ProfileData>& data) {
  double reach = 0;
  for (const ProfileData& d : data)
    if (d.radial.size() > 0) reach = std::max(reach, d.radial.r_mm.back());
  if (!(reach > 0)) throw Error("--fit-thickness: a slab's thickness is fitted from radial profiles");
  return reach;
}

// The log grid of trial thicknesses and its best point.
struct ThicknessGrid {
  std::vector<Trial> trials;
  std::size_t best = 0;
  double min_sigma_s_reduced = INFINITY;  ///< mm^-1, of the first fit: places the semi-infinite end
};

// Stage 3: chi^2 over a log grid of thicknesses.
ThicknessGrid scan_thickness_grid(ThicknessTrials& trial, double reach) {
  // The grid spans the tables' nodes (d sigma_s' 0.25 .. 256, the last the semi-infinite one) for
  // every channel, and past the last, at the sigma_s' of a first fit at the data's reach (a
  // slab's sigma_s' moves with d by far less than the factor of 2 of margin each end).
  const Trial first = trial(std::log(std::min(reach, kMaxThicknessMm)));
  if (!std::isfinite(first.chi2))
    throw Error("--fit-thickness: the data could not be fitted as a slab of " +
                std::to_string(reach) + " mm (their reach), the search's start");
  double s_lo = INFINITY, s_hi = 0;
  for (const ChannelFit& ch : first.result.chosen.channels)
    if (ch.samples > 0 && ch.sigma_s_reduced > 0)
      s_lo = std::min(s_lo, ch.sigma_s_reduced), s_hi = std::max(s_hi, ch.sigma_s_reduced);
  const double lo = std::log(std::max(0.125 / s_hi, 1e-4));
  const double hi = std::log(std::min(1024 / s_lo, kMaxThicknessMm));
  std::vector<Trial> grid;
  const int steps = std::max(4, int(std::ceil((hi - lo) / std::log(2.0))));
  for (int k = 0; k <= steps; ++k) grid.push_back(trial(lo + (hi - lo) * k / steps));
  std::size_t best = 0;
  for (std::size_t k = 1; k < grid.size(); ++k)
    if (grid[k].chi2 < grid[best].chi2) best = k;
  if (!std::isfinite(grid[best].chi2))
    throw Error("--fit-thickness: the data could not be fitted as a slab of any thickness");
  return {std::move(grid), best, s_lo};
}

// Stage 4: golden section in ln d within the grid cells that bracket the best point.
Trial refine_by_golden_section(ThicknessTrials& trial, const ThicknessGrid& scan) {
  const std::vector<Trial>& grid = scan.trials;
  const std::size_t best = scan.best;
  Trial opt = grid[best];
  double a = grid[best > 0 ? best - 1 : 0].log_d,
         b = grid[std::min(best + 1, grid.size() - 1)].log_d;
  constexpr double kInvPhi = 0.6180339887498949;
  Trial x1 = trial(b - kInvPhi * (b - a)), x2 = trial(a + kInvPhi * (b - a));
  while (b - a > 0.005) {
    if (x1.chi2 <= x2.chi2) {
      b = x2.log_d, x2 = x1, x1 = trial(b - kInvPhi * (b - a));
    } else {
      a = x1.log_d, x1 = x2, x2 = trial(a + kInvPhi * (b - a));
    }
  }
  for (const Trial* t : {&x1, &x2})
    if (t->chi2 < opt.chi2) opt = *t;
  return opt;
}

// Stage 5: the rise of chi^2 above the minimum that counts.
double chi2_rise_that_counts(const Trial& opt) {
  const ModelFit& at_best = opt.result.chosen;
  const int dof = std::max(1, at_best.samples - at_best.parameters);
  // One SD of the data (1, times the reduced chi^2 when above 1), or the fluctuation that swapping
  // one table node for another makes with the data held, which is larger: each thickness node is
  // its own Monte Carlo run, and on a semi-infinite skin capture (1e6 photons, 1e5 per node) chi^2
  // moved by 15-90 over 350 residuals between nodes the physics says are the same. sqrt(2 dof),
  // chi^2's own SD, is that scale.
  return std::max({1.0, opt.chi2 / dof, std::sqrt(2.0 * dof)});
}

// Stage 6: thick enough to be semi-infinite? The lit side alone fits a semi-infinite sample (grid
// points past the last node in every channel, with room for sigma_s' to move) within the bar.
bool fits_semi_infinite(const ThicknessGrid& scan, const Trial& opt, double delta, bool far) {
  // Then no thickness is pinned. Those points are one model, so their chi^2 should agree; they
  // differ by what the solver's restarts make (each restart weighs the table's error at its own
  // start values): 40 on the skin capture above. That spread widens the bar of this decision.
  double semi_chi2 = INFINITY, semi_spread = 0, semi_max = -INFINITY;
  for (const Trial& t : scan.trials)
    if (t.log_d >= std::log(384 / scan.min_sigma_s_reduced) && std::isfinite(t.chi2))
      semi_chi2 = std::min(semi_chi2, t.chi2), semi_max = std::max(semi_max, t.chi2);
  if (std::isfinite(semi_chi2)) semi_spread = semi_max - semi_chi2;
  return !far && semi_chi2 <= opt.chi2 + std::max(delta, semi_spread);
}

// An end of the interval in ln d, and whether it is closed (false: open, at the grid's edge).
using IntervalEnd = std::pair<double, bool>;

// The interval's end in one direction (-1: thinner, +1: thicker), walking out from the minimum over
// the grid, then bisection to the crossing. An end at the grid's edge is open (the data allow any
// thickness beyond it).
IntervalEnd find_crossing(ThicknessTrials& trial, const std::vector<Trial>& grid, const Trial& opt,
                          double bar, int direction) {
  double in = opt.log_d;  // known inside
  const int n = int(grid.size());
  for (int i = 0; i < n; ++i) {
    const Trial& g = grid[direction < 0 ? n - 1 - i : i];
    if (direction < 0 ? g.log_d >= opt.log_d : g.log_d <= opt.log_d) continue;
    if (g.chi2 > bar) {
      double out = g.log_d;
      for (int j = 0; j < 8; ++j) {
        const double mid = 0.5 * (in + out);
        (trial(mid).chi2 > bar ? out : in) = mid;
      }
      return {0.5 * (in + out), true};
    }
    in = g.log_d;
  }
  return {in, false};
}

// Stage 7: the interval's two ends (both open, at the grid's edges, for a semi-infinite answer).
std::pair<IntervalEnd, IntervalEnd> find_interval(ThicknessTrials& trial,
                                                  const std::vector<Trial>& grid, const Trial& opt,
                                                  double bar, bool semi_infinite) {
  IntervalEnd lower{grid.front().log_d, false}, upper{grid.back().log_d, false};
  if (!semi_infinite) {
    lower = find_crossing(trial, grid, opt, bar, -1);
    upper = find_crossing(trial, grid, opt, bar, +1);
  }
  return {lower, upper};
}

// Stage 8: the coefficients' largest shifts (sigma_a, sigma_s' per channel) from the fit at
// log_d to the fits at the interval's ends, given in ln d.
std::pair<std::array<double, 3>, std::array<double, 3>> coefficient_shifts(
    ThicknessTrials& trial, const double (&ends)[2], double log_d, const FitResult& result) {
  std::array<double, 3> shift_a{}, shift_s{};
  for (double e : ends) {
    if (std::abs(e - log_d) < 1e-9) continue;
    const Trial t = trial(e);
    if (!std::isfinite(t.chi2)) continue;
    for (int c = 0; c < 3; ++c) {
      shift_a[c] = std::max(shift_a[c], std::abs(t.result.chosen.channels[c].sigma_a -
                                                 result.chosen.channels[c].sigma_a));
      shift_s[c] = std::max(shift_s[c], std::abs(t.result.chosen.channels[c].sigma_s_reduced -
                                                 result.chosen.channels[c].sigma_s_reduced));
    }
  }
  return {shift_a, shift_s};
}

// Stage 9: the shifts join each fitted channel's systematic, and so its total, standard
// deviation.
void widen_systematics(const std::array<double, 3>& shift_a, const std::array<double, 3>& shift_s,
                       FitResult& result) {
  // An open end is the thinnest (or thickest) slab the data allow: the spread to it is said in
  // the note as well.
  for (ModelFit* f : {&result.chosen, &result.candidates.front()}) {
    for (int c = 0; c < 3; ++c) {
      ChannelFit& ch = f->channels[c];
      if (ch.samples == 0) continue;
      ch.sd_sys_sigma_a = std::hypot(ch.sd_sys_sigma_a, shift_a[c]);
      ch.sd_sys_sigma_s_reduced = std::hypot(ch.sd_sys_sigma_s_reduced, shift_s[c]);
      ch.sd_sigma_a = std::hypot(ch.sd_stat_sigma_a, ch.sd_sys_sigma_a);
      ch.sd_sigma_s_reduced = std::hypot(ch.sd_stat_sigma_s_reduced, ch.sd_sys_sigma_s_reduced);
    }
  }
}

// Stage 10: the note that says what the search found, first among the result's notes; an
// undetermined thickness is listed as such.
void add_thickness_note(const ThicknessFit& th, bool upper_closed, double log_d_best, int fits,
                        FitResult& result) {
  std::ostringstream note;
  note.precision(3);
  if (th.determined) {
    note << "thickness fitted: " << th.thickness_mm << " mm (1 SD interval " << th.lower_mm
         << ".." << th.upper_mm << " mm, from chi^2 over " << fits
         << " fits); the coefficients' spread over that interval is in their systematic";
  } else if (!upper_closed) {
    note << "thickness undetermined: the data fit any slab thicker than about " << th.lower_mm
         << " mm as well as a semi-infinite sample (the answer given is the semi-infinite one; its "
            "systematic spans the slab of " << th.lower_mm << " mm)";
    result.chosen.undetermined.push_back("the thickness (any above " + [&] {
      std::ostringstream s;
      s.precision(3);
      s << th.lower_mm;
      return s.str();
    }() + " mm fits)");
  } else {
    note << "thickness undetermined below: the data fit any slab thinner than about " << th.upper_mm
         << " mm (best " << std::exp(log_d_best) << " mm)";
    result.chosen.undetermined.push_back("the thickness (any below the fitted one fits)");
  }
  result.notes.insert(result.notes.begin(), note.str());
}

}  // namespace

FitResult fit_unknown_thickness(const std::vector<ProfileData>& data, const FitOptions& options) {
  check_thickness_options(options);
  const double reach = radial_reach_mm(data);

  ThicknessTrials trial(data, options);
  if (options.progress) options.progress("fitting the thickness", 0.0);
  const ThicknessGrid scan = scan_thickness_grid(trial, reach);
  const std::vector<Trial>& grid = scan.trials;
  const Trial opt = refine_by_golden_section(trial, scan);
  const double delta = chi2_rise_that_counts(opt);
  const double bar = opt.chi2 + delta;

  bool far = false;
  for (const ProfileData& d : data) far = far || d.transmitted;
  const bool semi_infinite = fits_semi_infinite(scan, opt, delta, far);

  const auto [lower, upper] = find_interval(trial, grid, opt, bar, semi_infinite);
  const auto [log_lower, lower_closed] = lower;
  const auto [log_upper, upper_closed] = upper;

  // The fit at the chosen thickness, and the interval in mm.
  ThicknessFit th;
  th.determined = !semi_infinite && upper_closed && lower_closed;
  th.lower_mm = lower_closed ? std::exp(log_lower) : 0.0;
  th.upper_mm = upper_closed ? std::exp(log_upper) : INFINITY;
  th.thickness_mm = upper_closed ? std::exp(opt.log_d) : INFINITY;
  // Open above: the answer is the semi-infinite fit itself (a far side: the thickest grid point).
  const double log_d = upper_closed ? opt.log_d : grid.back().log_d;
  FitOptions final_options = options;
  final_options.fit_thickness = false;
  if (upper_closed || far) final_options.thickness_mm = std::exp(log_d);
  if (options.progress) options.progress("the fit at the fitted thickness", 0.5);
  FitResult result = fit_profiles(data, final_options);
  // The thinnest slab a semi-infinite answer holds for (diffusion theory, within 10% over the
  // data's reach): what the data cannot tell from a semi-infinite sample.
  if (semi_infinite) th.lower_mm = result.assumed_thickness_mm;

  // The coefficients' spread over the interval joins their systematic (the larger shift of its two
  // ends; an open end is the grid's edge).
  const double ends[2] = {semi_infinite && th.lower_mm > 0 ? std::log(th.lower_mm)
                          : lower_closed                   ? log_lower
                                                           : grid.front().log_d,
                          upper_closed ? log_upper : grid.back().log_d};
  const auto [shift_a, shift_s] = coefficient_shifts(trial, ends, log_d, result);
  widen_systematics(shift_a, shift_s, result);
  th.fits = trial.fits();
  add_thickness_note(th, upper_closed, opt.log_d, trial.fits(), result);
  result.thickness = th;
  return result;
}

}  // namespace lucent::fit::detail
