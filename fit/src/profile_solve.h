// solve() (fit_solve.h) as named stages over one solve's state, the former locals of one long
// function, members under the same names. Building, constraining and running the problem are in
// fit_solve.cpp; the covariance, the channels' statistics and the check that the answer fits its
// data in fit_solve_answer.cpp.
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <array>
#include <chrono>
#include <deque>
#include <string>
#include <utility>
#include <vector>

#include "fit_residuals.h"
#include "fit_solve.h"
#include "fit_start.h"
#include "lucent/fit/fit.h"
#include "lucent/materials/tabulated.h"
#include "model_prediction.h"

namespace lucent::fit::detail {

struct SolveParameters {  // the parameters Ceres moves, and what the residual blocks point into
  std::array<std::array<double, 2>, 3> ab{};
  double log_scale = 0;
  double eta = 1.3;
  std::deque<std::array<double, 3>> calibration;  // per profile and channel: log scale with a prior
  std::deque<Observations> observations;          // owned: residual blocks point into it (stable)
};

// Describes a null-space vector over the free parameters ("0.71 log sigma_a[R] - 0.7 ...").
std::string describe_combination(const Eigen::VectorXd& v, const std::vector<std::string>& names);

// One solve (solve() below) as named stages over its state, the former locals of one long function
// under the same names: the problem built (a residual block per capture and channel, or per
// sample under a robust loss), constrained, solved, then the covariance and values, the channels'
// statistics and the check that the answer fits its data.
class ProfileSolve {
 public:
  ProfileSolve(const std::vector<ProfileData>& data, const FitOptions& options, FitModel model,
               const materials::TabulatedProfile* table, double eta0, bool relative,
               const std::array<double, 3>& exclude, const std::array<StartValues, 3>& start,
               std::array<bool, 3> channels, int* below_noise, ModelPerturbation perturbation,
               const std::array<double, 3>* hold_sigma_a)
      : data(data),
        options(options),
        model(model),
        table(table),
        eta0(eta0),
        relative(relative),
        exclude(exclude),
        start(start),
        channels(channels),
        below_noise(below_noise),
        perturbation(perturbation),
        hold_sigma_a(hold_sigma_a),
        q(quality_settings(options.quality)),
        gl(detail::gauss_legendre(q.footprint_order)) {}

  ModelFit run() {
    start_parameters();
    add_observations();
    check_samples_and_constrain();
    run_solver();
    if (!evaluate_at_solution()) return fit;
    covariance_and_values();
    channel_statistics();
    check_fit();
    fit.samples = samples[0] + samples[1] + samples[2];
    fit.aic = fit.chi2 + 2.0 * fit.parameters;
    fit.bic = fit.chi2 + fit.parameters * std::log(std::max(1, fit.samples));
    return fit;
  }

 private:
  void start_parameters();
  void add_observations();
  void weigh_with_table_error(Observations& o, int c);
  void add_per_sample_blocks(const Observations& o, const ProfileData& d, int c, double* scale);
  // Each residual block's samples, recorded beside block_channels.
  void record(int c, const Observations* o, int count) {
    block_channels.emplace_back(c, count);
    block_obs.push_back(o);
  }
  void check_samples_and_constrain();
  void run_solver();
  bool evaluate_at_solution();  // false: the model could not be evaluated (fit says so)
  void covariance_and_values();
  void channel_statistics();
  void check_fit();

  const std::vector<ProfileData>& data;
  const FitOptions& options;
  const FitModel model;
  const materials::TabulatedProfile* table;
  const double eta0;
  const bool relative;
  const std::array<double, 3>& exclude;
  const std::array<StartValues, 3>& start;
  const std::array<bool, 3> channels;
  int* below_noise;
  const ModelPerturbation perturbation;
  const std::array<double, 3>* hold_sigma_a;

  const QualitySettings q;
  const GaussLegendre gl;
  SolveParameters p;
  ceres::Problem problem;
  std::array<int, 3> samples{};
  std::array<double, 3> range_end{};
  std::vector<std::pair<int, int>> block_channels;  // (channel, residuals) in insertion order
  std::vector<const Observations*> block_obs;       // each block's samples (null: a prior)
  std::vector<std::pair<double*, std::string>> calibration_blocks;
  std::chrono::steady_clock::time_point t0;
  ceres::Solver::Summary summary;
  std::vector<double*> blocks;     // the free parameters' blocks ...
  std::vector<std::string> names;  // ... and their names
  ceres::CRSMatrix crs;            // the Jacobian at the solution
  std::vector<double> residuals;   // in residual-block order, for the per-channel statistics
  ModelFit fit;
};

}  // namespace lucent::fit::detail
