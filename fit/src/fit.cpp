#include "lucent/fit/fit.h"

#include <ceres/ceres.h>
#include <ceres/covariance.h>
#include <glog/logging.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <numbers>
#include <sstream>

#include "dipole_gradient.h"
#include "lucent/materials/albedo.h"
#include "lucent/materials/error.h"
#include "lucent/version.h"
#include "model_prediction.h"

namespace lucent::fit {
namespace {

using detail::CaptureGeometry;
using detail::GaussLegendre;

constexpr double kDegree = std::numbers::pi / 180.0;

CaptureGeometry geometry_of(const ProfileData& d) {
  CaptureGeometry g;
  const double theta = d.incidence_polar_deg * kDegree, phi = d.incidence_azimuth_deg * kDegree;
  g.cos_incidence = std::cos(theta);
  g.cos_view = std::cos(d.view_deg * kDegree);
  // The beam travels toward azimuth phi, so the light sits the other way.
  g.w_i = {-std::sin(theta) * std::cos(phi), -std::sin(theta) * std::sin(phi), std::cos(theta)};
  g.exitance = d.exitance;
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
};

// Residuals (log model - log data) * value / se: the log-ratio in units of the relative standard
// error. Parameters: {log sigma_a, log sigma_s'}, {log scale}, {eta}.
struct ProfileResiduals {
  const Observations* obs;
  FitModel model;
  GaussLegendre gl;

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
    const T log_front = log_scale + log(detail::fresnel_factor(
                                        obs->geometry, eta, model == FitModel::kDirectionalDipole));
    const std::size_t n = obs->log_value.size();
    if (model == FitModel::kDipole) {
      const materials::StandardDipole<T> dipole(medium);
      for (std::size_t i = 0; i < n; ++i) {
        const T v = obs->radial
                        ? detail::dipole_annulus(dipole, obs->r[i], obs->r0[i], obs->r1[i], gl)
                        : detail::dipole_pixel(dipole, obs->x[i], obs->y[i], obs->pixel, gl);
        residual[i] = (log_front + log(v + T(1e-300)) - obs->log_value[i]) * obs->inv_rel_se[i];
      }
    } else {
      const materials::DirectionalDipole<T> dd(medium);
      for (std::size_t i = 0; i < n; ++i) {
        const T v = obs->radial ? detail::ddipole_annulus(dd, obs->r[i], obs->r0[i], obs->r1[i], gl)
                                : detail::ddipole_pixel(dd, obs->geometry, obs->x[i], obs->y[i],
                                                        obs->pixel, gl);
        residual[i] = (log_front + log(v + T(1e-300)) - obs->log_value[i]) * obs->inv_rel_se[i];
      }
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
        parameters[1][0] + std::log(detail::fresnel_factor(obs_->geometry, *eta_, false));
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

// Far-field log-slope and total reflectance of one channel's radial bins: start values (DESIGN §6).
struct StartValues {
  double sigma_a = 0.01, sigma_s_reduced = 1.0, log_scale = 0.0;
};

double far_field_sigma_tr(const RadialBins& bins, int c) {
  std::vector<std::size_t> ok;
  for (std::size_t i = 0; i < bins.size(); ++i) {
    if (bins.value[c][i] > 3 * bins.standard_error[c][i] && bins.r_mm[i] > 0) ok.push_back(i);
  }
  if (ok.size() < 4) return 0.1;
  // The outer half of the usable bins: log(R r^3 / (1 + s r)) ~ const - s r.
  const std::vector<std::size_t> outer(ok.begin() + ok.size() / 2, ok.end());
  double s = 0.0;
  for (int iteration = 0; iteration < 4; ++iteration) {
    double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (std::size_t i : outer) {
      const double r = bins.r_mm[i];
      const double y = std::log(bins.value[c][i] * r * r * r / (1 + s * r));
      const double w = std::pow(bins.value[c][i] / bins.standard_error[c][i], 2);
      sw += w;
      sx += w * r;
      sy += w * y;
      sxx += w * r * r;
      sxy += w * r * y;
    }
    const double denominator = sw * sxx - sx * sx;
    if (!(denominator > 0)) break;
    s = std::max(1e-4, -(sw * sxy - sx * sy) / denominator);
  }
  return s;
}

double plane_total(const RadialBins& bins, int c, double sigma_tr) {
  double total = 0;
  for (std::size_t i = 0; i < bins.size(); ++i) {
    double r0 = bins.r_inner_mm[i], r1 = bins.r_outer_mm[i];
    if (!(r1 > r0)) {  // point samples: the annulus between the midpoints to the neighbours
      r0 = i == 0 ? 0.0 : 0.5 * (bins.r_mm[i - 1] + bins.r_mm[i]);
      r1 = i + 1 == bins.size() ? bins.r_mm[i] : 0.5 * (bins.r_mm[i] + bins.r_mm[i + 1]);
    }
    total += bins.value[c][i] * std::numbers::pi * (r1 * r1 - r0 * r0);
  }
  // Missing centre (first bin not at 0) and tail beyond the last bin: the far-field form
  // C e^(-s r)(1 + s r)/r^3 matched to the last bin, integrated analytically: 2 pi C e^(-s R) / R.
  if (bins.size() > 0) {
    const std::size_t last = bins.size() - 1;
    const double R = bins.r_outer_mm[last], r = bins.r_mm[last];
    const double C =
        bins.value[c][last] * r * r * r / ((1 + sigma_tr * r) * std::exp(-sigma_tr * r));
    if (std::isfinite(C) && C > 0) total += 2 * std::numbers::pi * C * std::exp(-sigma_tr * R) / R;
  }
  return total;
}

}  // namespace

GaussLegendre detail::gauss_legendre(int order) {
  // Golub-Welsch: nodes are the eigenvalues of the Jacobi matrix of the Legendre recurrence,
  // weights twice the squared first components of its eigenvectors; mapped from [-1, 1] to [0, 1].
  order = std::clamp(order, 1, 8);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(order, order);
  for (int k = 1; k < order; ++k) {
    const double beta = k / std::sqrt(4.0 * k * k - 1.0);
    J(k, k - 1) = J(k - 1, k) = beta;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(J);
  GaussLegendre gl;
  gl.order = order;
  for (int i = 0; i < order; ++i) {
    gl.node[i] = 0.5 * (eig.eigenvalues()(i) + 1.0);
    gl.weight[i] = eig.eigenvectors()(0, i) * eig.eigenvectors()(0, i);  // 2 v^2 / 2
  }
  return gl;
}

QualitySettings quality_settings(Quality quality) {
  QualitySettings s;
  switch (quality) {
    case Quality::kFast:
      s.footprint_order = 1;
      s.max_samples_2d = 1024;
      s.function_tolerance = 1e-6;
      s.parameter_tolerance = 1e-6;
      s.max_iterations = 50;
      break;
    case Quality::kBalanced:
      s.footprint_order = 2;  // two Gauss points are exact to fourth order across a bin
      break;
    case Quality::kAccurate:
      s.footprint_order = 6;
      s.max_samples_2d = 1 << 30;
      s.function_tolerance = 1e-14;
      s.parameter_tolerance = 1e-14;
      s.max_iterations = 500;
      break;
  }
  return s;
}

namespace {

const char* kChannelNames[3] = {"R", "G", "B"};

std::string model_name(FitModel m) {
  return m == FitModel::kDipole ? "dipole" : m == FitModel::kDirectionalDipole ? "ddipole" : "auto";
}

// Usable observations of one channel of one capture, after exclusion and the noise floor.
Observations observations_for(const ProfileData& d, int c, double exclude_mm, bool use_2d,
                              const QualitySettings& q, int* below_noise) {
  Observations o;
  o.geometry = geometry_of(d);
  const auto keep = [&](double v, double se) {
    if (!(se > 0) || !std::isfinite(v) || !std::isfinite(se)) return false;
    if (v < 2 * se) {  // below the noise floor: a log-ratio there is meaningless
      ++*below_noise;
      return false;
    }
    return true;
  };
  if (use_2d) {
    const Samples2d& s = *d.samples_2d;
    o.radial = false;
    o.pixel = s.pixel_mm;
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (std::hypot(s.x_mm[i], s.y_mm[i]) >= exclude_mm &&
          keep(s.value[c][i], s.standard_error[c][i])) {
        idx.push_back(i);
      }
    }
    const std::size_t stride =
        std::max<std::size_t>(1, (idx.size() + q.max_samples_2d - 1) / q.max_samples_2d);
    for (std::size_t k = 0; k < idx.size(); k += stride) {
      const std::size_t i = idx[k];
      o.x.push_back(s.x_mm[i]);
      o.y.push_back(s.y_mm[i]);
      o.log_value.push_back(std::log(s.value[c][i]));
      o.inv_rel_se.push_back(s.value[c][i] / s.standard_error[c][i]);
    }
  } else {
    const RadialBins& b = d.radial;
    if (b.pixel_mm > 0) {
      // Bins of pixel averages: model each as a pixel footprint at the bin's mean radius.
      o.radial = false;
      o.pixel = b.pixel_mm;
    }
    for (std::size_t i = 0; i < b.size(); ++i) {
      if (b.r_mm[i] < exclude_mm || !keep(b.value[c][i], b.standard_error[c][i])) continue;
      o.r.push_back(b.r_mm[i]);
      o.r0.push_back(b.r_inner_mm[i]);
      o.r1.push_back(b.r_outer_mm[i]);
      o.x.push_back(b.r_mm[i]);
      o.y.push_back(0.0);
      o.log_value.push_back(std::log(b.value[c][i]));
      o.inv_rel_se.push_back(b.value[c][i] / b.standard_error[c][i]);
    }
  }
  return o;
}

StartValues start_values(const ProfileData& d, int c, double eta, bool relative, bool search) {
  StartValues sv;
  const double sigma_tr = far_field_sigma_tr(d.radial, c);
  double alpha = 0.99;
  const double A = materials::derive_coefficients(materials::Medium<double>{0, 1, 0, eta}).A_dipole;
  const CaptureGeometry g = geometry_of(d);
  const double fresnel = detail::fresnel_factor(g, eta, false);
  if (!relative) {
    const double total = plane_total(d.radial, c, sigma_tr) / fresnel;
    if (total > 0 && total < 1)
      alpha = materials::reduced_albedo_from_total_reflectance(total, eta);
    alpha = std::clamp(alpha, 0.05, 1 - 1e-6);
  } else {
    // Unknown scale: the albedo whose dipole shape (for this sigma_tr) best matches the data, the
    // scale from the mean log-ratio.
    double best = INFINITY;
    for (double one_minus = 0.5; one_minus > 1e-6; one_minus *= 0.7) {
      const double a = 1 - one_minus;
      const double st = sigma_tr / std::sqrt(3 * (1 - a));
      const materials::StandardDipole<double> dipole(
          materials::Medium<double>::from_reduced((1 - a) * st, a * st, eta));
      double sum = 0, sum2 = 0;
      int n = 0;
      for (std::size_t i = 0; i < d.radial.size(); ++i) {
        const double v = d.radial.value[c][i];
        if (!(v > 2 * d.radial.standard_error[c][i]) || d.radial.r_mm[i] <= 0) continue;
        const double diff = std::log(v) - std::log(fresnel * dipole.R_d(d.radial.r_mm[i]));
        sum += diff;
        sum2 += diff * diff;
        ++n;
      }
      if (n < 2) break;
      const double spread = sum2 / n - (sum / n) * (sum / n);
      if (spread < best) {
        best = spread;
        alpha = a;
        sv.log_scale = sum / n;
      }
    }
  }
  (void)A;
  const double sigma_t_reduced = sigma_tr / std::sqrt(3 * (1 - alpha));
  sv.sigma_a = (1 - alpha) * sigma_t_reduced;
  sv.sigma_s_reduced = alpha * sigma_t_reduced;

  // The far-field slope and total need an exponential tail and most of the light inside the image;
  // a profile that ends within a diffusion length has neither. So also search a coarse grid of
  // (alpha', sigma_t') on a dozen bins and keep whichever start matches the data better: a few
  // thousand dipole evaluations, cheap next to the solve, and the solve starts in the right valley.
  std::vector<std::size_t> use;
  for (std::size_t i = 0; search && i < d.radial.size(); ++i) {
    if (d.radial.r_mm[i] > 0 && d.radial.value[c][i] > 2 * d.radial.standard_error[c][i])
      use.push_back(i);
  }
  if (use.size() >= 4) {
    std::vector<std::size_t> pick;
    for (int k = 0; k < 12; ++k)
      pick.push_back(use[std::min(use.size() - 1, k * (use.size() - 1) / 11)]);
    const double r_min = d.radial.r_mm[pick.front()], r_max = d.radial.r_mm[pick.back()];
    std::array<double, 12> log_data{}, w{};
    for (std::size_t k = 0; k < pick.size(); ++k) {
      const std::size_t i = pick[k];
      log_data[k] = std::log(d.radial.value[c][i]);
      const double inv_rel = d.radial.value[c][i] / d.radial.standard_error[c][i];
      w[k] = inv_rel * inv_rel;
    }
    const double log_fresnel = std::log(fresnel);
    const auto cost = [&](double sa, double ss, double* log_scale) {
      const materials::StandardDipole<double> dipole(materials::Medium<double>::from_reduced(sa, ss, eta));
      double sum = 0, sum2 = 0, wsum = 0;
      std::array<double, 12> diff{};
      for (std::size_t k = 0; k < pick.size(); ++k) {
        const double m = dipole.R_d(d.radial.r_mm[pick[k]]);
        if (!(m > 0)) return double(INFINITY);
        diff[k] = log_data[k] - log_fresnel - std::log(m);
        sum += w[k] * diff[k];
        wsum += w[k];
      }
      const double shift = relative ? sum / wsum : 0.0;
      for (std::size_t k = 0; k < pick.size(); ++k) sum2 += w[k] * (diff[k] - shift) * (diff[k] - shift);
      if (log_scale) *log_scale = shift;
      return sum2;
    };
    double best_shift = sv.log_scale;
    double best = cost(sv.sigma_a, sv.sigma_s_reduced, &best_shift);
    const double alphas[] = {0.05, 0.2,  0.4,   0.6,   0.8,   0.9,    0.95,
                             0.98, 0.99, 0.995, 0.998, 0.999, 0.9995, 0.9999};
    for (double a : alphas) {
      for (int k = 0; k < 16; ++k) {
        const double st = 0.2 / r_max * std::pow(100.0 * r_max / r_min, k / 15.0);
        double shift = 0;
        const double value = cost((1 - a) * st, a * st, &shift);
        if (value < best) {
          best = value;
          best_shift = shift;
          sv.sigma_a = (1 - a) * st;
          sv.sigma_s_reduced = a * st;
        }
      }
    }
    if (relative) sv.log_scale = best_shift;
  }
  return sv;
}

struct Problem {
  std::array<std::array<double, 2>, 3> ab{};
  double log_scale = 0;
  double eta = 1.3;
  std::deque<std::array<double, 3>> calibration;  // per profile and channel: log scale with a prior
  std::deque<Observations> observations;          // owned: residual blocks point into it (stable)
};

// Describes a null-space vector over the free parameters.
std::string describe_combination(const Eigen::VectorXd& v, const std::vector<std::string>& names) {
  std::ostringstream s;
  s.precision(2);
  bool first = true;
  for (int i = 0; i < v.size(); ++i) {
    if (std::abs(v(i)) < 0.05) continue;
    s << (first ? "" : (v(i) < 0 ? " - " : " + ")) << (first && v(i) < 0 ? "-" : "")
      << std::abs(v(i)) << " " << names[i];
    first = false;
  }
  return s.str();
}

ModelFit solve(const std::vector<ProfileData>& data, const FitOptions& options, FitModel model,
               double eta0, bool relative, double exclude_mm,
               const std::array<StartValues, 3>& start, std::array<bool, 3> channels,
               int* below_noise) {
  const QualitySettings q = quality_settings(options.quality);
  const GaussLegendre gl = detail::gauss_legendre(q.footprint_order);
  Problem p;
  p.eta = eta0;
  p.log_scale = relative ? start[0].log_scale : 0.0;
  for (int c = 0; c < 3; ++c) {
    p.ab[c] = {std::log(start[c].sigma_a), std::log(start[c].sigma_s_reduced)};
  }
  ceres::Problem problem;
  std::array<int, 3> samples{};
  std::vector<std::pair<int, int>> block_channels;  // (channel, residuals) in insertion order
  std::vector<std::pair<double*, std::string>> calibration_blocks;
  for (std::size_t di = 0; di < data.size(); ++di) {
    const ProfileData& d = data[di];
    const bool use_2d = d.samples_2d.has_value() && d.incidence_polar_deg > 0;
    p.calibration.push_back({0.0, 0.0, 0.0});
    for (int c = 0; c < 3; ++c) {
      if (!channels[c] || !d.channels[c]) continue;
      p.observations.push_back(observations_for(d, c, exclude_mm, use_2d, q, below_noise));
      const Observations& o = p.observations.back();
      if (o.log_value.empty()) continue;
      samples[c] += int(o.log_value.size());
      // The scale this capture's channel is known to: exact (held), fitted freely (relative), or
      // within the calibration's uncertainty (a prior).
      double* scale = &p.log_scale;
      const double cal_se = d.calibrated && !relative ? d.calibration_relative_se[c] : 0.0;
      if (cal_se > 0) {
        scale = &p.calibration.back()[c];
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<ScalePrior, 1, 1>(new ScalePrior{1.0 / cal_se}),
            nullptr, scale);
        block_channels.emplace_back(-1, 1);  // the prior's residual: not a sample
        calibration_blocks.emplace_back(
            scale, std::string("log calibration[") + kChannelNames[c] +
                       (data.size() > 1 ? ", input " + std::to_string(di + 1) : "") + "]");
      }
      const bool scale_free = scale != &p.log_scale || relative;
      if (options.loss == LossKind::kNone && !options.fit_ior && options.analytic_derivatives &&
          model == FitModel::kDipole) {
        problem.AddResidualBlock(new DipoleRadialCost(&o, gl, &p.eta), nullptr, p.ab[c].data(),
                                 scale);
        block_channels.emplace_back(c, int(o.log_value.size()));
      } else if (options.loss == LossKind::kNone && !options.fit_ior && !scale_free) {
        auto* cost = new ceres::AutoDiffCostFunction<ChannelResiduals, ceres::DYNAMIC, 2>(
            new ChannelResiduals{{&o, model, gl}, scale, &p.eta}, int(o.log_value.size()));
        problem.AddResidualBlock(cost, nullptr, p.ab[c].data());
        block_channels.emplace_back(c, int(o.log_value.size()));
      } else if (options.loss == LossKind::kNone) {
        auto* cost = new ceres::AutoDiffCostFunction<ProfileResiduals, ceres::DYNAMIC, 2, 1, 1>(
            new ProfileResiduals{&o, model, gl}, int(o.log_value.size()));
        problem.AddResidualBlock(cost, nullptr, p.ab[c].data(), scale, &p.eta);
        block_channels.emplace_back(c, int(o.log_value.size()));
      } else {
        // A robust loss acts on each sample, so each gets its own block.
        for (std::size_t i = 0; i < o.log_value.size(); ++i) {
          p.observations.push_back(o);
          Observations& one = p.observations.back();
          const auto pick = [&](std::vector<double>& v) {
            if (!v.empty()) v = {v[i]};
          };
          pick(one.r);
          pick(one.r0);
          pick(one.r1);
          pick(one.x);
          pick(one.y);
          pick(one.log_value);
          pick(one.inv_rel_se);
          auto* cost = new ceres::AutoDiffCostFunction<ProfileResiduals, ceres::DYNAMIC, 2, 1, 1>(
              new ProfileResiduals{&one, model, gl}, 1);
          ceres::LossFunction* loss =
              options.loss == LossKind::kHuber
                  ? static_cast<ceres::LossFunction*>(new ceres::HuberLoss(options.loss_scale))
                  : new ceres::CauchyLoss(options.loss_scale);
          problem.AddResidualBlock(cost, loss, p.ab[c].data(), scale, &p.eta);
          block_channels.emplace_back(c, 1);
        }
      }
    }
  }
  for (int c = 0; c < 3; ++c) {
    if (channels[c] && samples[c] < 2) {
      throw Error(std::string("fit: channel ") + kChannelNames[c] + " has " +
                  std::to_string(samples[c]) + " usable samples outside the exclusion radius (" +
                  std::to_string(exclude_mm) +
                  " mm) and above the noise floor; at least 2 are needed for sigma_a and sigma_s'");
    }
  }
  if (problem.HasParameterBlock(&p.log_scale) && !relative)
    problem.SetParameterBlockConstant(&p.log_scale);
  if (problem.HasParameterBlock(&p.eta)) {
    if (!options.fit_ior)
      problem.SetParameterBlockConstant(&p.eta);
    else
      problem.SetParameterLowerBound(&p.eta, 0, 1.0001),
          problem.SetParameterUpperBound(&p.eta, 0, 2.5);
  }

  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;  // 6 parameters: normal equations are tiny
  so.function_tolerance = q.function_tolerance;
  so.parameter_tolerance = q.parameter_tolerance;
  so.gradient_tolerance = 1e-14;
  so.max_num_iterations = options.max_iterations > 0 ? options.max_iterations : q.max_iterations;
  so.logging_type = ceres::SILENT;
  so.num_threads = 1;

  ModelFit fit;
  fit.model = model;
  const auto t0 = std::chrono::steady_clock::now();
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);

  // Which parameters are free, and is the problem well posed at the solution?
  std::vector<double*> blocks;
  std::vector<std::string> names;
  for (int c = 0; c < 3; ++c) {
    if (!channels[c]) continue;
    blocks.push_back(p.ab[c].data());
    names.push_back(std::string("log sigma_a[") + kChannelNames[c] + "]");
    names.push_back(std::string("log sigma_s'[") + kChannelNames[c] + "]");
  }
  if (relative) blocks.push_back(&p.log_scale), names.push_back("log scale");
  if (options.fit_ior) blocks.push_back(&p.eta), names.push_back("eta");
  for (const auto& [block, name] : calibration_blocks)
    blocks.push_back(block), names.push_back(name);

  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = blocks;
  ceres::CRSMatrix crs;
  std::vector<double> residuals;  // in residual-block order, for the per-channel statistics below
  problem.Evaluate(eo, nullptr, &residuals, nullptr, &crs);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int k = crs.rows[row]; k < crs.rows[row + 1]; ++k) J(row, crs.cols[k]) = crs.values[k];
  }
  Eigen::MatrixXd covariance;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeThinV);
  const Eigen::VectorXd sv = svd.singularValues();
  const double smax = sv.size() ? sv(0) : 0;
  Eigen::VectorXd inv2 = Eigen::VectorXd::Zero(sv.size());
  for (int i = 0; i < sv.size(); ++i) {
    // A direction is undetermined when the data cannot pin it within a factor e (its standard
    // deviation in log space, 1 / s, exceeds 1), or when it is numerically null.
    if (sv(i) > 1e-10 * smax && sv(i) > 1.0) {
      inv2(i) = 1.0 / (sv(i) * sv(i));
    } else {
      fit.undetermined.push_back(describe_combination(svd.matrixV().col(i), names));
    }
  }
  // (J^T J)^+ from the SVD: the covariance of the free parameters when the standard errors are
  // honest; directions the data does not determine are left out and reported instead.
  covariance = svd.matrixV() * inv2.asDiagonal() * svd.matrixV().transpose();
  fit.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  fit.converged = summary.termination_type == ceres::CONVERGENCE;
  fit.iterations = int(summary.iterations.size()) - 1;
  fit.message = summary.message;
  fit.chi2 = 2 * summary.final_cost;
  fit.eta = p.eta;
  fit.scale = std::exp(p.log_scale);
  for (int c = 0; c < 3; ++c) fit.calibration_scale[c] = std::exp(p.calibration.front()[c]);
  int k = 0;
  for (int c = 0; c < 3; ++c) {
    ChannelFit& ch = fit.channels[c];
    ch.start_sigma_a = start[c].sigma_a;
    ch.start_sigma_s_reduced = start[c].sigma_s_reduced;
    if (!channels[c]) continue;
    ch.sigma_a = std::exp(p.ab[c][0]);
    ch.sigma_s_reduced = std::exp(p.ab[c][1]);
    const double va = covariance(k, k), vs = covariance(k + 1, k + 1);
    ch.sd_sigma_a = ch.sigma_a * std::sqrt(std::max(0.0, va));  // delta method from log space
    ch.sd_sigma_s_reduced = ch.sigma_s_reduced * std::sqrt(std::max(0.0, vs));
    ch.correlation = va > 0 && vs > 0 ? covariance(k, k + 1) / std::sqrt(va * vs) : 0.0;
    ch.samples = samples[c];
    k += 2;
  }
  if (relative) fit.sd_scale = fit.scale * std::sqrt(std::max(0.0, covariance(k, k))), ++k;
  if (options.fit_ior) fit.sd_eta = std::sqrt(std::max(0.0, covariance(k, k))), ++k;
  k += int(calibration_blocks.size());
  fit.parameters = k;
  // Per-channel chi^2 and rms from the residuals at the solution.
  {
    std::size_t offset = 0;
    std::array<double, 3> chi2{};
    for (const auto& [c, count] : block_channels) {
      for (int i = 0; i < count; ++i, ++offset) {
        if (c >= 0) chi2[c] += residuals[offset] * residuals[offset];
      }
    }
    // fit.chi2 (AIC, BIC) keeps the calibration priors' share: a model that reaches the data only
    // by rescaling the calibration far beyond its uncertainty pays for it.
    for (int c = 0; c < 3; ++c) {
      fit.channels[c].chi2 = chi2[c];
      fit.channels[c].residual_rms = samples[c] ? std::sqrt(chi2[c] / samples[c]) : 0.0;
    }
  }
  fit.samples = samples[0] + samples[1] + samples[2];
  fit.aic = fit.chi2 + 2.0 * fit.parameters;
  fit.bic = fit.chi2 + fit.parameters * std::log(std::max(1, fit.samples));
  return fit;
}

}  // namespace

FitResult fit_profiles(const std::vector<ProfileData>& data, const FitOptions& options) {
  // Ceres logs (through glog) a warning with every residual of a rejected trial step that went
  // non-finite; the solver handles those steps itself, and a user should see our one-line errors
  // only. Errors still get through.
  static const bool quiet = [] {
    FLAGS_minloglevel = google::GLOG_ERROR;
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
  if (options.exclude_radius_mm) {
    result.exclude_radius_mm = *options.exclude_radius_mm;
  } else {
    // One transport mean free path, the largest over the channels.
    double mfp = 0;
    for (int c = 0; c < 3; ++c) {
      if (channels[c]) mfp = std::max(mfp, 1.0 / (start[c].sigma_a + start[c].sigma_s_reduced));
    }
    result.exclude_radius_mm = mfp;
  }

  std::vector<FitModel> models;
  if (options.model == FitModel::kAuto)
    models = {FitModel::kDipole, FitModel::kDirectionalDipole};
  else
    models = {options.model};
  int below_noise = 0;
  for (FitModel m : models) {
    below_noise = 0;
    ModelFit best = solve(data, options, m, eta0, relative, result.exclude_radius_mm, start,
                          channels, &below_noise);
    if (options.start) {
      // Given start values too; keep whichever start reaches the lower cost (a second start is the
      // cheap guard against the shallow valleys of low-albedo profiles).
      ModelFit other = solve(data, options, m, eta0, relative, result.exclude_radius_mm, given,
                             channels, &below_noise);
      if (other.chi2 <= best.chi2) best = other;
    }
    bool poor = !best.converged;
    for (int c = 0; c < 3; ++c) poor = poor || (channels[c] && best.channels[c].residual_rms > 3.0);
    if (poor) {
      // The far-field start can miss the valley (a profile that ends within a diffusion length has
      // no exponential tail and leaves light outside the image); search a grid of (alpha', sigma_t')
      // for a second start and keep the better solution.
      std::array<StartValues, 3> searched = start;
      for (int c = 0; c < 3; ++c) {
        if (channels[c]) searched[c] = start_values(data.front(), c, eta0, relative, true);
      }
      ModelFit other = solve(data, options, m, eta0, relative, result.exclude_radius_mm, searched,
                             channels, &below_noise);
      if (other.chi2 < best.chi2) best = other;
    }
    result.candidates.push_back(best);
  }
  if (below_noise > 0) {
    result.notes.push_back(std::to_string(below_noise) +
                           " samples below the noise floor (value < 2 standard errors) left out");
  }

  if (result.candidates.size() == 1) {
    result.chosen = result.candidates.front();
    result.reason = "model " + model_name(result.chosen.model) + " requested";
  } else {
    // The simplest model the data does not reject: the standard dipole unless the directional one
    // fits markedly better (AIC lower by more than 10, i.e. the dipole is e^5 = 150 times less
    // likely).
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
    result.reason = why.str();
  }
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
