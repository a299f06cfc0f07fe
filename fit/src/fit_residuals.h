// The residuals of a fit (docs/DESIGN.md §6): what one residual block measures (a run of radial
// bins or single pixels of one channel of one capture) and the Ceres cost functions over it, for
// every model. Internal to lucent_fit (fit_solve.cpp builds the problem from these).
#pragma once

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <memory>
#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include "convolution_2d.h"
#include "dipole_gradient.h"
#include "fit_solve.h"
#include "lucent/fit/fit.h"
#include "lucent/materials/tabulated.h"
#include "model_prediction.h"

namespace lucent::fit::detail {

constexpr double kDegree = std::numbers::pi / 180.0;

inline CaptureGeometry geometry_of(const ProfileData& d) {
  CaptureGeometry g;
  const double theta = d.incidence_polar_deg * kDegree, phi = d.incidence_azimuth_deg * kDegree;
  g.cos_incidence = std::cos(theta);
  g.cos_view = std::cos(d.view_deg * kDegree);
  // The beam travels toward azimuth phi, so the light sits the other way.
  g.w_i = {-std::sin(theta) * std::cos(phi), -std::sin(theta) * std::sin(phi), std::cos(theta)};
  g.exitance = d.exitance;
  g.per_incident_power = d.per_incident_power;
  if (d.thickness_mm) g.thickness_mm = *d.thickness_mm;
  g.transmitted = d.transmitted;
  return g;
}

// What one residual block measures: a run of radial bins or 2D samples of one channel of one
// capture.
struct Observations {
  bool radial = true;
  CaptureGeometry geometry;
  std::vector<double> r, r0, r1;   // radial
  std::vector<double> x, y;        // 2D
  double pixel = 0;                // footprint side of the pixels behind the samples, mm
  std::vector<double> log_value;   // log of the measurement
  std::vector<double> inv_rel_se;  // value / standard error: weights the log-ratio
  std::vector<double> data_rel_se;  // the data's own relative standard error (before the table's)
  // Single pixels (2D samples) are fitted in linear form, (model - value) / se: at their per-pixel
  // noise (10-40% in a faint tail) a log-ratio is biased (E log v < log E v) and a noise-floor cut
  // selects upward fluctuations; every pixel is kept, negative ones too. Then `value` and
  // `inv_se` are used, log_value holds log(max(value, se)) (sizes and plots only).
  bool linear = false;
  std::vector<double> value, inv_se, data_se;
  // The system response (system_response.h): the model is then sum_j conv_weights[i M + j]
  // f(conv_nodes[j]) at sample i, f the pencil-beam model at a point; empty: no convolution.
  std::vector<double> conv_nodes, conv_weights;
  // The response's value (per mm^2) at each sample: what the once-scattered point at the entry
  // becomes (single_scattering_point).
  std::vector<double> conv_point;
  // 2D samples with a system response (convolution_2d.h): the model on a grid of cells,
  // convolved, read at each sample; null: none.
  std::shared_ptr<const Convolution2d> conv2d;
  int capture = 0;  // index of the profile these come from
};

// Residuals (log model - log data) * value / se: the log-ratio in units of the relative standard
// error. Parameters: {log sigma_a, log sigma_s'}, {log scale}, {eta}.
struct ProfileResiduals {
  const Observations* obs;
  FitModel model;
  GaussLegendre gl;
  const materials::TabulatedProfile* table = nullptr;  // kTabulated only
  ModelPerturbation perturbation{};

  template <typename T>
  bool operator()(const T* const ab, const T* const log_scale, const T* const eta,
                  T* residual) const {
    return evaluate(ab, log_scale[0], eta[0], residual);
  }

  template <typename T>
  bool evaluate(const T* const ab, const T& log_scale, const T& eta, T* residual) const {
    using std::exp;
    using std::log;
    const materials::Medium<T> medium =
        materials::Medium<T>::from_reduced(exp(ab[0]), exp(ab[1]), eta);
    const T log_front = log_scale + log(detail::fresnel_factor(obs->geometry, eta, model));
    const std::size_t n = obs->log_value.size();
    // The tabulated model is built once per evaluation (its rows at these coefficients), then
    // read at every sample.
    std::optional<materials::TabulatedModel<T>> tab;
    std::optional<materials::DirectionalDipole<T>> dd;  // oblique 2D data: the corrected ddipole
    std::optional<materials::ObliqueModel<T>> ob;  // or the oblique table, where there is one
    const bool oblique = !obs->radial && obs->geometry.cos_incidence < 0.9999;
    if (model == FitModel::kTabulated) {
      if (oblique && table->oblique())
        ob.emplace(*table->oblique(), medium);
      else
        tab.emplace(*table, medium, obs->geometry.thickness_mm, obs->geometry.transmitted);
    }
    if (tab && oblique) dd.emplace(medium);
    const materials::TableQuantity q = detail::table_quantity(obs->geometry);
    // With a system response: the pencil-beam model at the nodes once, then each sample a
    // weighted sum of them (the convolution, precomputed).
    std::vector<T> at_nodes;
    if (!obs->conv_nodes.empty()) {
      at_nodes.reserve(obs->conv_nodes.size());
      for (const double s : obs->conv_nodes)
        at_nodes.push_back(tab ? tab->at(q, T(s))
                               : detail::model_value(model, table, medium, obs->geometry, true, s,
                                                     s, s, s, 0.0, 0.0, gl));
    }
    const std::size_t m = obs->conv_nodes.size();
    // The once-scattered point, for the accurate model (which holds single scattering), at the
    // table's g: sigma_s = sigma_s' / (1 - g) (the diffusion models have no single scattering).
    T point(0);
    if (m > 0 && model == FitModel::kTabulated && table) {
      const double g = table->g();
      point = detail::single_scattering_point(
          materials::Medium<T>{medium.sigma_a, medium.sigma_s / T(1 - g), T(g), eta},
          obs->geometry);
    }
    // The model at one 2D point over a footprint of side `pixel`.
    const auto pixel_value = [&](double x, double y, double pixel) -> T {
      return ob ? detail::oblique_pixel(*ob, q, obs->geometry, x, y, pixel, gl)
             : tab ? (oblique ? detail::corrected_ddipole_pixel(*tab, *dd, q, obs->geometry, x, y,
                                                                pixel, gl)
                              : detail::tabulated_pixel(*tab, q, x, y, pixel, gl))
                   : detail::model_value(model, table, medium, obs->geometry, false, 0.0, 0.0,
                                         0.0, x, y, pixel, gl);
    };
    std::vector<T> grid;
    if (const Convolution2d* c2 = obs->conv2d.get()) {
      grid.resize(std::size_t(c2->nx) * std::size_t(c2->ny));
      for (int yj = 0; yj < c2->ny; ++yj)
        for (int xi = 0; xi < c2->nx; ++xi)
          grid[std::size_t(yj) * c2->nx + xi] = pixel_value(c2->cell_x(xi), c2->cell_y(yj), c2->h);
      convolve(*c2, grid);
    }
    for (std::size_t i = 0; i < n; ++i) {
      T convolved(0);
      if (m > 0) {
        const double* w = obs->conv_weights.data() + i * m;
        for (std::size_t j = 0; j < m; ++j)
          if (w[j] != 0) convolved += w[j] * at_nodes[j];
        convolved += point * obs->conv_point[i];
      }
      T v(0);
      if (const Convolution2d* c2 = obs->conv2d.get()) {
        for (std::size_t k = 0; k < 4; ++k)
          if (c2->weights[i][k] != 0) v += c2->weights[i][k] * grid[std::size_t(c2->cells[i][k])];
      } else if (m > 0) {
        v = convolved;
      } else if (!obs->radial) {
        v = pixel_value(obs->x[i], obs->y[i], obs->pixel);
      } else {
        v = tab ? detail::tabulated_annulus(*tab, q, obs->r[i], obs->r0[i], obs->r1[i], gl)
                : detail::model_value(model, table, medium, obs->geometry, true, obs->r[i],
                                      obs->r0[i], obs->r1[i], obs->x[i], obs->y[i], obs->pixel, gl);
      }
      T scaled = v;
      if (perturbation.epsilon != 0) {
        const double r = obs->radial ? obs->r[i] : std::hypot(obs->x[i], obs->y[i]);
        scaled *= perturbation.factor(T(r) * (medium.sigma_a + medium.sigma_s));
      }
      if (obs->linear)
        residual[i] = (exp(log_front) * scaled - obs->value[i]) * obs->inv_se[i];
      else
        residual[i] = (log_front + log(scaled + T(1e-300)) - obs->log_value[i]) * obs->inv_rel_se[i];
    }
    return true;
  }
};

// The common case, scale and eta held: derivatives in the two channel parameters only (Jets of 2,
// not 4: half the work).
struct ChannelResiduals {
  ProfileResiduals full;
  const double* log_scale;
  const double* eta;

  template <typename T>
  bool operator()(const T* const ab, T* residual) const {
    return full.evaluate(ab, T(*log_scale), T(*eta), residual);
  }
};

// The scale free (a calibration prior, or a relative fit) and eta held: the residual is affine in
// the scale's factor exp(log scale) (linear form) or in log scale itself (log-ratio form), so its
// column is analytic and only {log sigma_a, log sigma_s'} need Jets: Jets of 2, not the 4 of
// ProfileResiduals over {ab, log scale, eta}, half the derivative work of the 2D fits, which spend
// most of their time in Jet arithmetic. The same solution and covariance as the AutoDiff
// ProfileResiduals (fit_residuals_test.cpp holds them together).
class ScaledChannelCost : public ceres::CostFunction {
 public:
  // Parameter blocks: {log sigma_a, log sigma_s'} and {log scale}.
  ScaledChannelCost(ProfileResiduals full, const double* eta) : full_(full), eta_(eta) {
    set_num_residuals(int(full.obs->log_value.size()));
    mutable_parameter_block_sizes()->push_back(2);
    mutable_parameter_block_sizes()->push_back(1);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* ab = parameters[0];
    const double log_scale = parameters[1][0];
    if (!jacobians) return full_.evaluate(ab, log_scale, *eta_, residuals);
    using Jet2 = ceres::Jet<double, 2>;
    const Jet2 ab_jet[2] = {Jet2(ab[0], 0), Jet2(ab[1], 1)};
    std::vector<Jet2> r(static_cast<std::size_t>(num_residuals()));
    if (!full_.evaluate(ab_jet, Jet2(log_scale), Jet2(*eta_), r.data())) return false;
    const Observations& o = *full_.obs;
    for (std::size_t i = 0; i < r.size(); ++i) {
      residuals[i] = r[i].a;
      if (jacobians[0]) jacobians[0][2 * i] = r[i].v[0], jacobians[0][2 * i + 1] = r[i].v[1];
      // Linear: r = (e^s m - v) / se, so dr/ds = e^s m / se = r + v / se; log-ratio: dr/ds = w.
      if (jacobians[1])
        jacobians[1][i] = o.linear ? r[i].a + o.value[i] * o.inv_se[i] : o.inv_rel_se[i];
    }
    return true;
  }

 private:
  ProfileResiduals full_;
  const double* eta_;
};

// The standard dipole with a hand-written Jacobian (scale and eta held): annuli, or pixel
// footprints.
class DipoleRadialCost : public ceres::CostFunction {
 public:
  // Parameter blocks: {log sigma_a, log sigma_s'} and {log scale}.
  DipoleRadialCost(const Observations* obs, GaussLegendre gl, const double* eta)
      : obs_(obs), gl_(gl), eta_(eta) {
    set_num_residuals(int(obs->log_value.size()));
    mutable_parameter_block_sizes()->push_back(2);
    mutable_parameter_block_sizes()->push_back(1);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* ab = parameters[0];
    const detail::DipoleGradientModel model(std::exp(ab[0]), std::exp(ab[1]), *eta_);
    const double log_front =
        parameters[1][0] +
        std::log(detail::fresnel_factor(obs_->geometry, *eta_, FitModel::kDipole));
    for (std::size_t i = 0; i < obs_->log_value.size(); ++i) {
      detail::DipoleGradient sum;
      const auto add = [&](double weight, double r) {
        const detail::DipoleGradient g = model.at(r);
        sum.value += weight * g.value;
        sum.d_log_sigma_a += weight * g.d_log_sigma_a;
        sum.d_log_sigma_s += weight * g.d_log_sigma_s;
      };
      if (!obs_->radial) {  // a pixel footprint (2D sample, or a bin of pixel averages)
        const double p = obs_->pixel;
        if (!(p > 0)) {
          add(1.0, std::hypot(obs_->x[i], obs_->y[i]));
        } else {
          for (int a = 0; a < gl_.order; ++a) {
            for (int b = 0; b < gl_.order; ++b) {
              add(gl_.weight[a] * gl_.weight[b], std::hypot(obs_->x[i] + (gl_.node[a] - 0.5) * p,
                                                            obs_->y[i] + (gl_.node[b] - 0.5) * p));
            }
          }
        }
      } else if (!(obs_->r1[i] > obs_->r0[i])) {
        add(1.0, obs_->r[i]);
      } else {
        const double r0 = obs_->r0[i], r1 = obs_->r1[i];
        for (int k = 0; k < gl_.order; ++k)
          add(gl_.weight[k], std::sqrt(r0 * r0 + gl_.node[k] * (r1 * r1 - r0 * r0)));
      }
      const double v = sum.value + 1e-300;
      const double w = obs_->inv_rel_se[i];
      residuals[i] = (log_front + std::log(v) - obs_->log_value[i]) * w;
      if (jacobians && jacobians[0]) {
        jacobians[0][2 * i] = w * sum.d_log_sigma_a / v;
        jacobians[0][2 * i + 1] = w * sum.d_log_sigma_s / v;
      }
      if (jacobians && jacobians[1]) jacobians[1][i] = w;
    }
    return true;
  }

 private:
  const Observations* obs_;
  GaussLegendre gl_;
  const double* eta_;
};

// Prior on a calibration scale: log scale ~ N(0, relative_se).
struct ScalePrior {
  double inverse_se;
  template <typename T>
  bool operator()(const T* const log_scale, T* residual) const {
    residual[0] = log_scale[0] * inverse_se;
    return true;
  }
};


/// Usable observations of one channel of one capture, after exclusion and the noise floor.
Observations observations_for(const ProfileData& d, int c, double exclude_mm, bool use_2d,
                              const QualitySettings& q, int* below_noise);

}  // namespace lucent::fit::detail
