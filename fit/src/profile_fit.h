// fit_profiles (fit.cpp) as named stages over one fit's state, the former locals of one long
// function, now members under the same names. The stages that fit (the inputs read, the start
// values, the table, the candidate models) are in fit.cpp; those that judge the answer (the choice,
// the table's systematic, the slab's range, the cheaper models and g, what it assumes) in
// fit_answer.cpp.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "fit_solve.h"
#include "fit_start.h"
#include "fit_uncertainty.h"
#include "lucent/fit/fit.h"
#include "lucent/materials/tabulated.h"

namespace lucent::fit::detail {

// Shares of a default fit's time before each stage, for the progress line (measured on the bundled
// marble_45deg, a 2D oblique fit of about 12 s; a radial fit takes under a second and shows none).
inline constexpr double kShareTabulated = 0.03, kShareDirectional = 0.10,
                        kShareTableSystematic = 0.17, kShareAdequacy = 0.42;

// One fit: run() is the stages in order.
class ProfileFit {
 public:
  ProfileFit(const std::vector<ProfileData>& input, const FitOptions& o) : data(input), options(o) {}

  FitResult run() {
    check_inputs();
    choose_starts();
    choose_table();
    fit_candidates();
    choose_model();
    if (tab_ok && options.systematics && result.chosen.model == FitModel::kTabulated)
      table_systematic();
    detail::finish_uncertainty(result, options, channels);
    check_slab_range();
    judge_cheaper_models_and_g();
    state_assumptions();
    return std::move(result);
  }

 private:
  void report(const char* stage, double done) const {
    if (options.progress) options.progress(stage, done);
  }
  void check_inputs();
  void choose_starts();
  void choose_table();
  std::array<double, 3> exclusion(FitModel m, const std::array<StartValues, 3>& st) const;
  ModelFit fit_model(FitModel m, const std::array<StartValues, 3>& first);
  std::array<StartValues, 3> started_from(const ModelFit& f) const;
  void fit_candidates();
  void choose_model();
  void table_systematic();
  void check_slab_range();
  void judge_cheaper_models_and_g();
  void state_assumptions();

  std::vector<ProfileData> data;  // the inputs, each with its slab thickness
  const FitOptions& options;
  bool slab = false;          // a slab of given thickness (else semi-infinite)
  double eta0 = 1.4;          // the relative index (its start, when it is fitted)
  bool relative = false;      // the calibration scale is fitted
  std::array<bool, 3> channels{false, false, false};  // the channels that hold data
  std::array<StartValues, 3> start, given;  // from the data; from the options (else the same)
  bool oblique = false;       // 2D samples at oblique incidence
  std::shared_ptr<const materials::TabulatedProfile> full, fixed;  // every eta; this eta
  std::string table_problem;  // why the tabulated model does not apply ("" when it does)
  std::string oblique_source;  // the oblique table's slice in use
  bool tab_ok = false;
  const materials::TabulatedProfile* tab = nullptr;  // the tabulated model in use
  double pixel_mm = 0;        // the widest pixel of the inputs
  int below_noise = 0;        // samples left out as below the noise (by the last solve)
  FitResult result;
};

}  // namespace lucent::fit::detail
