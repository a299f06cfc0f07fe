// The fit's outputs: the material file and the report.
#include <cmath>

#include "lucent/fit/fit.h"
#include "lucent/version.h"

namespace lucent::fit {
namespace {

using nlohmann::json;

std::string name_of(FitModel m) {
  return m == FitModel::kDipole ? "dipole" : m == FitModel::kDirectionalDipole ? "ddipole" : "auto";
}

std::string name_of(Quality q) {
  return q == Quality::kFast ? "fast" : q == Quality::kBalanced ? "balanced" : "accurate";
}

json finite_or_null(double v) {
  return std::isfinite(v) ? json(v) : json(nullptr);
}

json model_fit_json(const ModelFit& f) {
  json channels = json::array();
  for (const ChannelFit& c : f.channels) {
    channels.push_back({{"sigma_a", finite_or_null(c.sigma_a)},
                        {"sigma_s_reduced", finite_or_null(c.sigma_s_reduced)},
                        {"sd_sigma_a", finite_or_null(c.sd_sigma_a)},
                        {"sd_sigma_s_reduced", finite_or_null(c.sd_sigma_s_reduced)},
                        {"correlation", finite_or_null(c.correlation)},
                        {"start_sigma_a", finite_or_null(c.start_sigma_a)},
                        {"start_sigma_s_reduced", finite_or_null(c.start_sigma_s_reduced)},
                        {"samples", c.samples},
                        {"chi2", finite_or_null(c.chi2)},
                        {"residual_rms", finite_or_null(c.residual_rms)}});
  }
  return {{"model", name_of(f.model)},
          {"channels", channels},
          {"eta", f.eta},
          {"sd_eta", f.sd_eta},
          {"scale", f.scale},
          {"sd_scale", f.sd_scale},
          {"calibration_scale", f.calibration_scale},
          {"converged", f.converged},
          {"iterations", f.iterations},
          {"time_ms", f.time_ms},
          {"chi2", finite_or_null(f.chi2)},
          {"samples", f.samples},
          {"parameters", f.parameters},
          {"aic", finite_or_null(f.aic)},
          {"bic", finite_or_null(f.bic)},
          {"undetermined", f.undetermined},
          {"message", f.message}};
}

json inputs_json(const std::vector<ProfileData>& data) {
  json inputs = json::array();
  for (const ProfileData& d : data) inputs.push_back(d.source);
  return inputs.size() == 1 ? inputs[0] : inputs;
}

}  // namespace

materials::Material fitted_material(const FitResult& result, const std::vector<ProfileData>& data,
                                    const FitOptions& options, const std::string& name) {
  const ModelFit& f = result.chosen;
  materials::Material m;
  m.name = name;
  m.ior = f.eta;
  m.model = name_of(f.model);
  json sd_a = json::array(), sd_s = json::array(), corr = json::array();
  for (int c = 0; c < 3; ++c) {
    m.sigma_a[c] = f.channels[c].sigma_a;
    m.sigma_s_reduced[c] = f.channels[c].sigma_s_reduced;
    sd_a.push_back(f.channels[c].sd_sigma_a);
    sd_s.push_back(f.channels[c].sd_sigma_s_reduced);
    corr.push_back(f.channels[c].correlation);
  }
  m.uncertainty = {{"sigma_a", sd_a},
                   {"sigma_s_reduced", sd_s},
                   {"correlation_sigma_a_sigma_s_reduced", corr},
                   {"kind", "one standard deviation, from the Jacobian at the solution"}};
  if (options.fit_ior) m.uncertainty["ior"] = f.sd_eta;
  if (!f.undetermined.empty()) m.uncertainty["undetermined"] = f.undetermined;
  int residuals = 0;
  double chi2 = 0;
  for (const ChannelFit& c : f.channels) residuals += c.samples, chi2 += c.chi2;
  m.provenance = {{"tool", std::string("lucent fit ") + kVersion},
                  {"fit",
                   {{"input", inputs_json(data)},
                    {"model", name_of(f.model)},
                    {"model_choice", result.reason},
                    {"samples", f.samples},
                    {"exclude_radius_mm", result.exclude_radius_mm},
                    {"residual_rms", residuals ? std::sqrt(chi2 / residuals) : 0.0},
                    {"iterations", f.iterations},
                    {"converged", f.converged},
                    {"time_ms", f.time_ms},
                    {"quality", name_of(options.quality)},
                    {"scale", f.scale},
                    {"notes", result.notes}}}};
  return m;
}

json fit_report(const FitResult& result, const std::vector<ProfileData>& data,
                const FitOptions& options) {
  json candidates = json::array();
  for (const ModelFit& f : result.candidates) candidates.push_back(model_fit_json(f));
  return {{"format", "lucent-fit-report"},
          {"version", 1},
          {"input", inputs_json(data)},
          {"chosen", model_fit_json(result.chosen)},
          {"candidates", candidates},
          {"reason", result.reason},
          {"exclude_radius_mm", result.exclude_radius_mm},
          {"quality", name_of(options.quality)},
          {"relative", options.relative.value_or(false)},
          {"notes", result.notes},
          {"tool", std::string("lucent fit ") + kVersion}};
}

}  // namespace lucent::fit
