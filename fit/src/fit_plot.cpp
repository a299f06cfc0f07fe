#include "lucent/fit/fit_plot.h"

#include <cmath>
#include <cstdio>
#include <numbers>

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
  // What the fit compares with: a pixel footprint at r when the bins are pixel averages.
  const detail::GaussLegendre gl = detail::gauss_legendre(2);
  const double p = data.radial.pixel_mm;
  const double v = detail::model_value(fit.model, table, medium, g, false, r, r, r, r, 0.0, p, gl);
  return fit.scale * fit.calibration_scale[c] * detail::fresnel_factor(g, fit.eta, fit.model) * v;
}

void write_fit_plot(const std::filesystem::path& path, const FitResult& result,
                    const ProfileData& data) {
  using imaging::PlotPanel;
  using imaging::PlotSeries;
  const std::array<std::array<std::uint8_t, 3>, 3> colours{
      {{200, 30, 30}, {30, 150, 30}, {30, 60, 210}}};
  const std::array<std::array<std::uint8_t, 3>, 3> light{
      {{240, 160, 160}, {150, 210, 150}, {160, 175, 240}}};
  const char* names[3] = {"R", "G", "B"};
  const ModelFit& f = result.chosen;
  PlotPanel profile;
  profile.title = "profile: data (points, +-1 SE) and " + to_string(f.model) +
                  " fit (lines); excluded region in light colours; y: " +
                  (data.calibrated ? "pi L / P (1/mm^2)" : "pi L (relative)");
  profile.x_label = "r (mm)";
  profile.log_y = true;
  profile.height_weight = 2.2;
  PlotPanel residuals;
  residuals.title = "residuals: log(model / data) / relative SE (lines at 0 and +-2)";
  residuals.x_label = "r (mm)";
  residuals.horizontal_lines = {0.0, -2.0, 2.0};
  const RadialBins& b = data.radial;
  double r_max = 0;
  for (double r : b.r_mm) r_max = std::max(r_max, r);
  for (int c = 0; c < 3; ++c) {
    if (!data.channels[c]) continue;
    PlotSeries used, excluded, res;
    used.rgb = res.rgb = colours[c];
    used.label = std::string("data ") + names[c];
    excluded.rgb = light[c];
    for (std::size_t i = 0; i < b.size(); ++i) {
      const bool in = b.r_mm[i] >= result.exclude_radius_mm;
      PlotSeries& s = in ? used : excluded;
      s.x.push_back(b.r_mm[i]);
      s.y.push_back(b.value[c][i]);
      s.y_error.push_back(b.standard_error[c][i]);
      if (in && b.value[c][i] > 0) {
        const double m = predicted_radial(f, data, c, b.r_mm[i], result.table.get());
        res.x.push_back(b.r_mm[i]);
        res.y.push_back(std::log(m / b.value[c][i]) * b.value[c][i] / b.standard_error[c][i]);
      }
    }
    PlotSeries curve;
    curve.rgb = colours[c];
    curve.markers = false;
    curve.line = true;
    curve.label = std::string("fit ") + names[c];
    for (int k = 0; k <= 300; ++k) {
      const double r = r_max * k / 300.0;
      curve.x.push_back(r);
      curve.y.push_back(predicted_radial(f, data, c, r, result.table.get()));
    }
    profile.series.push_back(excluded);
    profile.series.push_back(used);
    profile.series.push_back(curve);
    residuals.series.push_back(res);
  }
  std::vector<std::string> footer;
  char line[256];
  for (int c = 0; c < 3; ++c) {
    if (!data.channels[c]) continue;
    const ChannelFit& ch = f.channels[c];
    std::snprintf(line, sizeof line,
                  "%s: sigma_a = %.4g +- %.2g /mm   sigma_s' = %.4g +- %.2g /mm   corr %.2f   rms "
                  "%.2f SE (%d samples)",
                  names[c], ch.sigma_a, ch.sd_sigma_a, ch.sigma_s_reduced, ch.sd_sigma_s_reduced,
                  ch.correlation, ch.residual_rms, ch.samples);
    footer.push_back(line);
  }
  std::snprintf(line, sizeof line,
                "eta %.3f, scale %.4g, calibration %.4f %.4f %.4f, exclusion radius %.3g mm, %s in "
                "%d iterations, %.2f ms",
                f.eta, f.scale, f.calibration_scale[0], f.calibration_scale[1],
                f.calibration_scale[2], result.exclude_radius_mm,
                f.converged ? "converged" : "NOT converged", f.iterations, f.time_ms);
  footer.push_back(line);
  footer.push_back("model choice: " + result.reason);
  imaging::write_plot_png(path, {profile, residuals}, footer, 1100, 900);
}

}  // namespace lucent::fit
