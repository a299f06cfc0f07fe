// The fit's outputs: the material file and the report.
#include <cmath>

#include "lucent/fit/fit.h"
#include "lucent/version.h"

namespace lucent::fit {
namespace {

using nlohmann::json;

std::string name_of(FitModel m) {
  return to_string(m);
}

std::string name_of(Quality q) {
  return q == Quality::kFast ? "fast" : q == Quality::kBalanced ? "balanced" : "accurate";
}

json finite_or_null(double v) {
  return std::isfinite(v) ? json(v) : json(nullptr);
}

// --fit-thickness: null unless fitted; an open end is null (thickness_mm null: semi-infinite).
json thickness_json(const FitResult& result) {
  if (!result.thickness) return nullptr;
  const ThicknessFit& t = *result.thickness;
  return {{"thickness_mm", finite_or_null(t.thickness_mm)},
          {"lower_mm", t.lower_mm > 0 ? json(t.lower_mm) : json(nullptr)},
          {"upper_mm", finite_or_null(t.upper_mm)},
          {"determined", t.determined},
          {"fits", t.fits}};
}

json model_fit_json(const ModelFit& f) {
  json channels = json::array();
  for (const ChannelFit& c : f.channels) {
    channels.push_back({{"sigma_a", finite_or_null(c.sigma_a)},
                        {"sigma_s_reduced", finite_or_null(c.sigma_s_reduced)},
                        {"sd_sigma_a", finite_or_null(c.sd_sigma_a)},
                        {"sd_sigma_s_reduced", finite_or_null(c.sd_sigma_s_reduced)},
                        {"sd_stat_sigma_a", finite_or_null(c.sd_stat_sigma_a)},
                        {"sd_stat_sigma_s_reduced", finite_or_null(c.sd_stat_sigma_s_reduced)},
                        {"sd_sys_sigma_a", finite_or_null(c.sd_sys_sigma_a)},
                        {"sd_sys_sigma_s_reduced", finite_or_null(c.sd_sys_sigma_s_reduced)},
                        {"reduced_chi2", finite_or_null(c.reduced_chi2)},
                        {"design_effect", finite_or_null(c.design_effect)},
                        {"structure_z", finite_or_null(c.structure_z)},
                        {"exclude_radius_mm", finite_or_null(c.exclude_radius_mm)},
                        {"range_end_mm", finite_or_null(c.range_end_mm)},
                        {"range_diffusion_lengths", finite_or_null(c.range_diffusion_lengths)},
                        {"correlation", finite_or_null(c.correlation)},
                        {"start_sigma_a", finite_or_null(c.start_sigma_a)},
                        {"start_sigma_s_reduced", finite_or_null(c.start_sigma_s_reduced)},
                        {"samples", c.samples},
                        {"chi2", finite_or_null(c.chi2)},
                        {"residual_rms", finite_or_null(c.residual_rms)},
                        {"robust_residual_rms", finite_or_null(c.robust_residual_rms)}});
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

json adequacy_json(const FitResult& r) {
  json a = json::array();
  for (const ModelAdequacy& m : r.adequacy)
    a.push_back({{"model", name_of(m.model)},
                 {"bar_percent", 100 * ModelAdequacy::kBar},
                 {"within_percent", 100 * m.tolerance},
                 {"within_percent_beyond_mm", finite_or_null(m.beyond_mm)},
                 {"max_deviation_percent", finite_or_null(100 * m.max_deviation)},
                 {"adequate", m.adequate}});
  return a;
}

json g_systematic_json(const FitResult& r) {
  if (r.g_09.empty()) return nullptr;
  json shift_a = json::array(), shift_s = json::array();
  for (int c = 0; c < 3; ++c) {
    shift_a.push_back(finite_or_null(r.g_09[c][0] - r.chosen.channels[c].sigma_a));
    shift_s.push_back(finite_or_null(r.g_09[c][1] - r.chosen.channels[c].sigma_s_reduced));
  }
  return {{"assumed_g", r.g},
          {"other_g", r.g_other},
          {"shift_sigma_a", shift_a},
          {"shift_sigma_s_reduced", shift_s},
          {"note", "radial normal-incidence data cannot separate g from sigma_s: the fit at "
                   "other_g moves by these amounts (mm^-1); not in the total, which holds for "
                   "the assumed g"}};
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
  m.adequate_model = result.adequate_model;
  m.fallback_model = result.fallback_model;
  // A tabulated fit at an assumed g > 0 measured that medium: the file says so (sigma_s and g
  // beside sigma_s'), so that lucent profile and the renderers evaluate the model at the same g.
  // (Not when sigma_s would pass the 1e6 mm^-1 a material file may hold: sigma_s' alone then.)
  bool anisotropic = f.model == FitModel::kTabulated && result.g > 0 && result.g < 1;
  for (int c = 0; anisotropic && c < 3; ++c)
    anisotropic = f.channels[c].sigma_s_reduced / (1 - result.g) <= 1e6;
  if (anisotropic) {
    m.g = materials::Rgb{result.g, result.g, result.g};
    m.sigma_s = materials::Rgb{};
    for (int c = 0; c < 3; ++c) (*m.sigma_s)[c] = f.channels[c].sigma_s_reduced / (1 - result.g);
  }
  json sd_a = json::array(), sd_s = json::array(), corr = json::array();
  json stat_a = json::array(), stat_s = json::array(), sys_a = json::array(), sys_s = json::array();
  for (int c = 0; c < 3; ++c) {
    const ChannelFit& ch = f.channels[c];
    m.sigma_a[c] = ch.sigma_a;
    m.sigma_s_reduced[c] = ch.sigma_s_reduced;
    sd_a.push_back(ch.sd_sigma_a);
    sd_s.push_back(ch.sd_sigma_s_reduced);
    stat_a.push_back(ch.sd_stat_sigma_a);
    stat_s.push_back(ch.sd_stat_sigma_s_reduced);
    sys_a.push_back(ch.sd_sys_sigma_a);
    sys_s.push_back(ch.sd_sys_sigma_s_reduced);
    corr.push_back(ch.correlation);
  }
  m.uncertainty = {
      {"sigma_a", sd_a},
      {"sigma_s_reduced", sd_s},
      {"statistical", {{"sigma_a", stat_a}, {"sigma_s_reduced", stat_s}}},
      {"systematic", {{"sigma_a", sys_a}, {"sigma_s_reduced", sys_s}}},
      {"correlation_sigma_a_sigma_s_reduced", corr},
      {"kind",
       "one standard deviation, mm^-1: total = statistical (Jacobian at the solution, "
       "calibration prior included, scaled by the root of the reduced chi^2 or, for pixels, the design effect, when above 1) and "
       "systematic "
       "(the model's own error: a diffusion model's difference from the tabulated model on the "
       "same data) in quadrature"}};
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
                    {"g", result.g},
                    {"g_systematic", g_systematic_json(result)},
                    {"adequate_model", result.adequate_model},
                    {"fallback_model", result.fallback_model},
                    {"adequacy", adequacy_json(result)},
                    {"fitted_thickness", thickness_json(result)},
                    {"warnings", result.warnings},
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
          {"warnings", result.warnings},
          {"g", result.g},
          {"assumed_thickness_mm", finite_or_null(result.assumed_thickness_mm)},
          {"fitted_thickness", thickness_json(result)},
          {"g_systematic", g_systematic_json(result)},
          {"adequate_model", result.adequate_model},
          {"fallback_model", result.fallback_model},
          {"adequacy", adequacy_json(result)},
          {"tool", std::string("lucent fit ") + kVersion}};
}

}  // namespace lucent::fit
