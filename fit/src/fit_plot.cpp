#include "lucent/fit/fit_plot.h"
#include "system_response.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include "fit_residuals.h"
#include "lucent/core/error.h"
#include "lucent/imaging/plot.h"
#include "model_prediction.h"

namespace lucent::fit {

double predicted_radial(const ModelFit& fit, const ProfileData& data, int c, double r,
                        const materials::TabulatedProfile* table) {
  const materials::Medium<double> medium = materials::Medium<double>::from_reduced(
      fit.channels[c].sigma_a, fit.channels[c].sigma_s_reduced, fit.eta);
  detail::CaptureGeometry g;
  g.cos_incidence = std::cos(data.incidence_polar_deg * std::numbers::pi / 180);
  g.cos_view = std::cos(data.view_deg * std::numbers::pi / 180);
  g.exitance = data.exitance;
  g.per_incident_power = data.per_incident_power;
  if (data.thickness_mm) g.thickness_mm = *data.thickness_mm;
  g.transmitted = data.transmitted;
  // What the fit compares with: a pixel footprint at r when the bins are pixel averages.
  const detail::GaussLegendre gl = detail::gauss_legendre(2);
  const double p = data.radial.pixel_mm;
  const double front =
      fit.scale * fit.calibration_scale[c] * detail::fresnel_factor(g, fit.eta, fit.model);
  // A system response (the white reference's, or the fit's --beam-sigma-mm): the fit's own
  // convolved model at r, through its residual functor (log data 0, weight 1: the residual is the
  // log of the prediction).
  detail::Observations o;
  o.geometry = detail::geometry_of(data);
  o.r = o.r0 = o.r1 = o.x = {r};
  o.y = {0.0};
  o.pixel = p;
  o.radial = !(p > 0);
  o.log_value = {0.0};
  o.inv_rel_se = {1.0};
  o.data_rel_se = {1.0};
  if (!detail::attach_system_response(o, data, fit.beam_sigma_mm).empty()) {
    const detail::ProfileResiduals model{&o, fit.model, gl, table};
    const double ab[2] = {std::log(fit.channels[c].sigma_a),
                          std::log(fit.channels[c].sigma_s_reduced)};
    double log_v = 0;
    model.evaluate(ab, std::log(fit.scale * fit.calibration_scale[c]), fit.eta, &log_v);
    return std::exp(log_v);
  }
  const double v = detail::model_value(fit.model, table, medium, g, false, r, r, r, r, 0.0, p, gl);
  return front * v;
}

void check_fit_plot_path(const std::filesystem::path& path, const std::string& option) {
  try {
    imaging::plot_format(path);
  } catch (const Error&) {
    throw Error(option + ": '" + path.string() + "': expected a file ending in .svg, .pdf or .png");
  }
}

namespace {

using imaging::Marker;
using imaging::PlotPanel;
using imaging::PlotSeries;
using Rgb = std::array<std::uint8_t, 3>;

const std::array<Rgb, 3> kColours{{{200, 30, 30}, {30, 140, 30}, {30, 60, 210}}};
const std::array<Rgb, 3> kLight{{{240, 170, 170}, {160, 215, 160}, {170, 185, 240}}};
// The fits: darker, so that a line shows over its own channel's markers.
const std::array<Rgb, 3> kDark{{{110, 0, 0}, {0, 75, 0}, {0, 20, 110}}};
const std::array<Marker, 3> kMarkers{Marker::kCircle, Marker::kSquare, Marker::kTriangle};
const char* const kNames[3] = {"R", "G", "B"};

// Every 2D sample of channel c with the model there, computed as the fit computes it (the same
// observations and residual functor, fit_residuals.h): residual = (model - value) / se.
struct PixelFit {
  std::vector<double> x, y, value, se, model, residual;
};

PixelFit pixel_fit(const FitResult& result, const ProfileData& d, int c) {
  const ModelFit& f = result.chosen;
  QualitySettings all;
  all.max_samples_2d = std::numeric_limits<int>::max();  // every sample, none skipped
  int below_noise = 0;
  const detail::Observations o = detail::observations_for(d, c, 0.0, true, all, &below_noise);
  PixelFit p;
  if (o.value.empty()) return p;
  const detail::ProfileResiduals model{&o, f.model, detail::gauss_legendre(2), result.table.get()};
  const double ab[2] = {std::log(f.channels[c].sigma_a), std::log(f.channels[c].sigma_s_reduced)};
  p.residual.resize(o.value.size());
  model.evaluate(ab, std::log(f.scale * f.calibration_scale[c]), f.eta, p.residual.data());
  p.x = o.x, p.y = o.y, p.value = o.value, p.se = o.data_se;
  for (std::size_t i = 0; i < o.value.size(); ++i)
    p.model.push_back(o.value[i] + p.residual[i] * o.data_se[i]);
  return p;
}

// The residual map of one channel: pixels (beyond the exclusion radius) summed into square cells
// of k x k pixels, each cell sum(residual) / sqrt(n): unit variance where the model fits.
imaging::PlotMap residual_map(const PixelFit& p, double pixel, double exclude, int c) {
  imaging::PlotMap map;
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (std::size_t i = 0; i < p.x.size(); ++i) {
    x0 = std::min(x0, p.x[i]), x1 = std::max(x1, p.x[i]);
    y0 = std::min(y0, p.y[i]), y1 = std::max(y1, p.y[i]);
  }
  if (!(pixel > 0)) pixel = std::max(x1 - x0, y1 - y0) / 96;
  if (!(x1 >= x0) || !(pixel > 0)) return map;
  const double cell = pixel * std::max(1.0, std::ceil(std::max(x1 - x0, y1 - y0) / pixel / 96));
  map.x_min = x0 - 0.5 * pixel, map.y_min = y0 - 0.5 * pixel;
  map.nx = std::max(1, int(std::ceil((x1 + 0.5 * pixel - map.x_min) / cell - 1e-6)));
  map.ny = std::max(1, int(std::ceil((y1 + 0.5 * pixel - map.y_min) / cell - 1e-6)));
  map.x_max = map.x_min + map.nx * cell, map.y_max = map.y_min + map.ny * cell;
  std::vector<double> sum(std::size_t(map.nx) * map.ny, 0.0), count(sum.size(), 0.0);
  for (std::size_t i = 0; i < p.x.size(); ++i) {
    if (std::hypot(p.x[i], p.y[i]) < exclude || !std::isfinite(p.residual[i])) continue;
    const int ix = std::clamp(int((p.x[i] - map.x_min) / cell), 0, map.nx - 1);
    const int iy = std::clamp(int((p.y[i] - map.y_min) / cell), 0, map.ny - 1);
    sum[std::size_t(iy) * map.nx + ix] += p.residual[i];
    count[std::size_t(iy) * map.nx + ix] += 1;
  }
  for (std::size_t k = 0; k < sum.size(); ++k)
    map.values.push_back(count[k] > 0 ? sum[k] / std::sqrt(count[k]) : NAN);
  map.title = std::string(kNames[c]);
  return map;
}

// Radial bins of the 2D samples: data mean with its standard error, the model's mean over the same
// pixels, and the bin's residual sum(model - value) / sqrt(sum se^2).
struct BinnedProfile {
  std::vector<double> r, value, se, model, residual;
};

BinnedProfile radial_average(const PixelFit& p, double width) {
  double r_max = 0;
  for (std::size_t i = 0; i < p.x.size(); ++i) r_max = std::max(r_max, std::hypot(p.x[i], p.y[i]));
  const std::size_t n = std::size_t(r_max / width) + 1;
  std::vector<double> count(n), r(n), v(n), var(n), m(n);
  for (std::size_t i = 0; i < p.x.size(); ++i) {
    const double ri = std::hypot(p.x[i], p.y[i]);
    const std::size_t k = std::min(n - 1, std::size_t(ri / width));
    count[k] += 1, r[k] += ri, v[k] += p.value[i], var[k] += p.se[i] * p.se[i], m[k] += p.model[i];
  }
  BinnedProfile b;
  for (std::size_t k = 0; k < n; ++k) {
    if (!(count[k] > 0) || !(var[k] > 0)) continue;
    b.r.push_back(r[k] / count[k]);
    b.value.push_back(v[k] / count[k]);
    b.se.push_back(std::sqrt(var[k]) / count[k]);
    b.model.push_back(m[k] / count[k]);
    b.residual.push_back((m[k] - v[k]) / std::sqrt(var[k]));
  }
  return b;
}

std::vector<std::string> footer_of(const FitResult& result, const ProfileData& data) {
  const ModelFit& f = result.chosen;
  std::vector<std::string> footer;
  char line[320];
  for (int c = 0; c < 3; ++c) {
    if (!data.channels[c]) continue;
    const ChannelFit& ch = f.channels[c];
    std::snprintf(line, sizeof line,
                  "%s: σ_a = %.4g ± %.2g /mm,  σ_s' = %.4g ± %.2g /mm,  correlation %.2f,  rms "
                  "%.2f SE (%d samples)",
                  kNames[c], ch.sigma_a, ch.sd_sigma_a, ch.sigma_s_reduced, ch.sd_sigma_s_reduced,
                  ch.correlation, ch.residual_rms, ch.samples);
    footer.push_back(line);
  }
  std::snprintf(line, sizeof line,
                "η %.3f,  scale %.4g,  calibration %.4f %.4f %.4f,  exclusion radius %.3g mm,  %s "
                "in %d iterations, %.2f ms",
                f.eta, f.scale, f.calibration_scale[0], f.calibration_scale[1],
                f.calibration_scale[2], result.exclude_radius_mm,
                f.converged ? "converged" : "NOT converged", f.iterations, f.time_ms);
  footer.push_back(line);
  footer.push_back("model choice: " + result.reason);
  return footer;
}

}  // namespace

void write_fit_plot(const std::filesystem::path& path, const FitResult& result,
                    const ProfileData& data, FitPlotOptions options) {
  imaging::plot_format(path);  // before the work
  const ModelFit& f = result.chosen;
  const bool oblique = data.samples_2d.has_value() && data.incidence_polar_deg > 0;  // as fitted
  const bool maps = data.samples_2d.has_value() && data.samples_2d->size() > 0 &&
                    (f.model != FitModel::kTabulated || result.table);
  const std::string r_label = options.log_r ? "r (mm, log)" : "r (mm)";
  PlotPanel profile;
  char incidence[64];
  std::snprintf(incidence, sizeof incidence, "%.0f°", data.incidence_polar_deg);
  profile.title = oblique ? "Radial averages of the 2D samples (" + std::string(incidence) +
                                " incidence): data (markers, ±1 SE) and the " + to_string(f.model) +
                                " fit over the same pixels (lines); light: not fitted"
                          : "Radial profile: data (markers, ±1 SE) and the " + to_string(f.model) +
                                " fit (lines); light: not fitted";
  profile.x_label = r_label;
  profile.y_label = data.calibrated ? "πL / P (1/mm²)" : "πL (relative)";
  profile.log_x = options.log_r;
  profile.log_y = true;
  profile.height_weight = 2.2;
  PlotPanel residuals;
  residuals.title = oblique ? "Residuals of the radial averages: (model − data) / SE, lines at 0 "
                              "and ±2"
                            : "Residuals: log(model / data) / relative SE (the fit's weighting), "
                              "lines at 0 and ±2";
  residuals.x_label = r_label;
  residuals.y_label = "residual (SE)";
  residuals.log_x = options.log_r;
  residuals.reference_lines = {{0.0}, {2.0, false, true}, {-2.0, false, true}};
  PlotPanel map_panel;
  map_panel.title =
      "Residual map (model − data) / SE per pixel, summed over cells / √n; grey: "
      "excluded or masked";
  map_panel.x_label = "x (mm)";
  map_panel.y_label = "y (mm)";
  map_panel.colour_label = "(model − data) / SE";
  map_panel.height_weight = 1.6;
  PlotSeries not_fitted;
  not_fitted.rgb = {170, 170, 170};
  not_fitted.label = "not fitted";
  double worst = 3;
  for (int c = 0; c < 3; ++c) {
    if (!data.channels[c]) continue;
    const ChannelFit& ch = f.channels[c];
    PlotSeries used, excluded, curve, res;
    used.rgb = res.rgb = kColours[c];
    curve.rgb = kDark[c];
    excluded.rgb = kLight[c];
    used.marker = excluded.marker = res.marker = kMarkers[c];
    used.label = std::string(kNames[c]) + " data";
    curve.label = std::string(kNames[c]) + " fit";
    curve.markers = false, curve.line = true;
    const auto add = [&](double r, double v, double se, bool in) {
      PlotSeries& s = in ? used : excluded;
      s.x.push_back(r), s.y.push_back(v), s.y_error.push_back(se);
    };
    PixelFit pixels;
    if (maps) pixels = pixel_fit(result, data, c);
    if (oblique) {
      const double pixel = data.samples_2d->pixel_mm > 0 ? data.samples_2d->pixel_mm : 0.25;
      const BinnedProfile b = radial_average(pixels, pixel);
      for (std::size_t i = 0; i < b.r.size(); ++i) {
        const bool in = b.r[i] >= ch.exclude_radius_mm;
        add(b.r[i], b.value[i], b.se[i], in);
        curve.x.push_back(b.r[i]), curve.y.push_back(b.model[i]);
        if (in) res.x.push_back(b.r[i]), res.y.push_back(b.residual[i]);
      }
    } else {
      const RadialBins& b = data.radial;
      double r_min = INFINITY, r_max = 0;
      for (std::size_t i = 0; i < b.size(); ++i) {
        const double v = b.value[c][i], se = b.standard_error[c][i];
        const bool in = b.r_mm[i] >= ch.exclude_radius_mm && b.r_mm[i] <= ch.range_end_mm + 1e-9;
        add(b.r_mm[i], v, se, in);
        if (b.r_mm[i] > 0) r_min = std::min(r_min, b.r_mm[i]);
        r_max = std::max(r_max, b.r_mm[i]);
        if (in && v >= 2 * se && se > 0) {  // the fit's noise floor
          const double m = predicted_radial(f, data, c, b.r_mm[i], result.table.get());
          res.x.push_back(b.r_mm[i]);
          res.y.push_back(std::log(m / v) * v / se);
        }
      }
      // The curve: 300 radii over the data's, evenly spaced on the r axis as drawn. Not from r = 0:
      // the tabulated and dipole profiles diverge there (a y axis to 1e16).
      const bool log = options.log_r && std::isfinite(r_min);
      const double r_lo = std::isfinite(r_min) ? r_min : 0;
      for (int k = 0; k <= 300 && r_max > r_lo; ++k) {
        const double r =
            log ? r_min * std::pow(r_max / r_min, k / 300.0) : r_lo + (r_max - r_lo) * k / 300.0;
        curve.x.push_back(r);
        curve.y.push_back(predicted_radial(f, data, c, r, result.table.get()));
      }
    }
    for (double v : res.y)
      if (std::isfinite(v)) worst = std::max(worst, std::abs(v));
    profile.series.push_back(excluded);
    profile.series.push_back(used);
    profile.series.push_back(curve);
    residuals.series.push_back(res);
    if (maps) {
      const double pixel = data.samples_2d->pixel_mm;
      imaging::PlotMap map = residual_map(pixels, pixel, ch.exclude_radius_mm, c);
      if (!map.values.empty()) map_panel.maps.push_back(std::move(map));
    }
  }
  profile.series.push_back(not_fitted);
  residuals.y_min = -1.08 * worst, residuals.y_max = 1.08 * worst;
  imaging::PlotFigure figure;
  figure.panels = {profile, residuals};
  figure.share_x = true;
  figure.footer = footer_of(result, data);
  figure.width = 1100, figure.height = 950;
  if (!map_panel.maps.empty()) {
    figure.panels.push_back(map_panel);
    figure.height = 1350;
  }
  imaging::write_plot(path, figure);
}

}  // namespace lucent::fit
