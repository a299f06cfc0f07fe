#include "lucent/fit/fit_bench.h"

#include "lucent/core/json_file.h"

#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <ostream>
#include <sstream>

#include "lucent/acquire/acquire.h"
#include "lucent/acquire/simulate.h"
#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/fit/fit.h"
#include "lucent/imaging/plot.h"

namespace lucent::fit {
namespace {

namespace fs = std::filesystem;

struct BenchCase {
  std::string name;
  ProfileData data;
  materials::Material truth;
  bool monte_carlo = false;  ///< made by photon transport (else by a diffusion model)
};

// Simulated with a diffusion model as the source: the truth is exact for that model.
BenchCase model_case(const std::string& name, const std::string& material,
                     acquire::RadianceSource source, double incidence_deg, int size,
                     const fs::path& scratch) {
  acquire::SimulateOptions o;
  o.material = materials::load_material(material);
  o.source = source;
  o.transport.size = size;
  o.transport.pixel_mm = 0.3;
  o.transport.incidence_deg = incidence_deg;
  o.transport.seed = 7;  // drives the camera noise too
  const fs::path sim = scratch / (name + "-sim"), acq = scratch / (name + "-acq");
  acquire::run_simulation(o, sim);
  acquire::run_acquire(sim / "capture.json", acq);
  return {name, load_profile_data(acq / "profile.json"), o.material};
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

// Stage 1 of the bench: the captures with known truth, three made by diffusion models and the
// bundled Monte Carlo capture when it is there.
std::vector<BenchCase> prepare_cases(const FitBenchOptions& options, const fs::path& scratch,
                                     std::ostream& log) {
  std::vector<BenchCase> cases;
  log << "bench fit: preparing captures\n";
  cases.push_back(model_case("potato-dipole-0deg", "potato", acquire::RadianceSource::kDipole, 0,
                             options.size_px, scratch));
  cases.push_back(model_case("skin1-ddipole-0deg", "skin1",
                             acquire::RadianceSource::kDirectionalDipole, 0, options.size_px,
                             scratch));
  cases.push_back(model_case("marble-ddipole-45deg", "marble",
                             acquire::RadianceSource::kDirectionalDipole, 45, options.size_px,
                             scratch));
  if (fs::exists(options.sample_capture)) {
    const fs::path acq = scratch / "sample-acq";
    acquire::run_acquire(options.sample_capture, acq);
    const auto truth = read_json_file(options.sample_capture.parent_path() / "truth.json");
    cases.push_back({"marble-montecarlo-0deg", load_profile_data(acq / "profile.json"),
                     materials::material_from_json(truth["material"], "truth.json"), true});
  } else {
    log << "bench fit: " << options.sample_capture
        << " not found; the Monte Carlo case is skipped\n";
  }
  return cases;
}

// One case fitted `repeats` times with one setting: the last result and the median time.
struct TimedFit {
  FitResult result;
  double time_ms = 0;
};

// Stage 2a of the bench: times one setting on one case.
TimedFit time_fit(const BenchCase& bc, const FitOptions& fo, int repeats) {
  std::vector<double> times;
  FitResult result;
  for (int k = 0; k < repeats; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    result = fit_profiles({bc.data}, fo);
    times.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  return {std::move(result), median(times)};
}

// A fit's errors against the truth, averaged over the channels that were fitted.
struct ParameterErrors {
  double sigma_a = 0, sigma_s_reduced = 0;  // mean |fitted / truth - 1|
  double residual_rms = 0;
};

// Stage 2b of the bench: how far one fit is from its case's truth.
ParameterErrors parameter_errors(const FitResult& result, const materials::Material& truth) {
  double err_a = 0, err_s = 0, rms = 0;
  int n = 0;
  for (int c = 0; c < 3; ++c) {
    const ChannelFit& f = result.chosen.channels[c];
    if (f.samples == 0) continue;
    err_a += std::abs(f.sigma_a / truth.sigma_a[c] - 1);
    err_s += std::abs(f.sigma_s_reduced / truth.sigma_s_reduced[c] - 1);
    rms += f.residual_rms;
    ++n;
  }
  err_a /= n, err_s /= n, rms /= n;
  return {err_a, err_s, rms};
}

// One setting's point on the trade plot.
struct TradePoint {
  double time_ms, error;
  int series;  // index into TradeCurves::series_names
};

// The sweep's points, one series per case, model and derivatives through the three qualities.
struct TradeCurves {
  std::vector<TradePoint> points;
  std::vector<std::string> series_names;
  int settings = 0;
};

// Stage 2 of the bench: every setting on every case, a CSV row and a log line each.
TradeCurves sweep_settings(const std::vector<BenchCase>& cases, int repeats, std::ostream& csv,
                           std::ostream& log) {
  csv << "case,model,quality,derivatives,time_ms_median,samples,sigma_a_rel_error,"
         "sigma_s_reduced_rel_error,residual_rms\n";
  TradeCurves curves;
  const char* quality_names[3] = {"fast", "balanced", "accurate"};
  for (const BenchCase& bc : cases) {
    // The tabulated model (exact to transport) on the Monte Carlo capture, whose truth is
    // transport; on a model-made capture only that model is exact, so it is left out there.
    std::vector<FitModel> models{FitModel::kDipole, FitModel::kDirectionalDipole};
    if (bc.monte_carlo) models.push_back(FitModel::kTabulated);
    for (FitModel model : models) {
      for (bool analytic : {true, false}) {
        if (analytic && model != FitModel::kDipole) continue;  // analytic Jacobian: dipole only
        const std::string model_name = to_string(model);
        const std::string series =
            bc.name + " / " + model_name +
            (model == FitModel::kDipole ? (analytic ? " analytic" : " autodiff") : "");
        curves.series_names.push_back(series);
        for (int q = 0; q < 3; ++q) {
          FitOptions fo;
          fo.model = model;
          fo.quality = Quality(q);
          fo.analytic_derivatives = analytic;
          fo.allow_unconverged = true;
          const TimedFit timed = time_fit(bc, fo, repeats);
          const auto [err_a, err_s, rms] = parameter_errors(timed.result, bc.truth);
          const double t = timed.time_ms;
          csv << bc.name << ',' << model_name << ',' << quality_names[q] << ','
              << (model == FitModel::kDipole && analytic ? "analytic" : "automatic") << ',' << t
              << ',' << timed.result.chosen.samples << ',' << err_a << ',' << err_s << ',' << rms
              << '\n';
          curves.points.push_back(
              {t, std::max(1e-7, 0.5 * (err_a + err_s)), int(curves.series_names.size()) - 1});
          log << "  " << series << ", " << quality_names[q] << ": " << t << " ms, sigma_a error "
              << 100 * err_a << "%, sigma_s' error " << 100 * err_s << "%\n";
          ++curves.settings;
        }
      }
    }
  }
  return curves;
}

// Stage 3 of the bench: the trade curves as one plot, error against time.
void write_trade_plot(const TradeCurves& curves, const fs::path& path) {
  imaging::PlotPanel panel;
  panel.title =
      "Fit speed against accuracy: mean relative parameter error against median solve time, "
      "one curve per case and model through fast, balanced and accurate";
  panel.x_label = "time per fit (ms)";
  panel.y_label = "mean relative error of σ_a and σ_s'";
  // Logarithmic where the values span decades (they usually do).
  double t_lo = INFINITY, t_hi = 0, e_lo = INFINITY, e_hi = 0;
  for (const TradePoint& p : curves.points) {
    t_lo = std::min(t_lo, p.time_ms), t_hi = std::max(t_hi, p.time_ms);
    e_lo = std::min(e_lo, p.error), e_hi = std::max(e_hi, p.error);
  }
  panel.log_x = t_lo > 0 && t_hi > 20 * t_lo;
  panel.log_y = e_lo > 0 && e_hi > 20 * e_lo;
  const std::array<std::array<std::uint8_t, 3>, 8> palette{{{200, 30, 30},
                                                            {30, 140, 30},
                                                            {30, 60, 210},
                                                            {200, 120, 0},
                                                            {140, 0, 160},
                                                            {0, 150, 150},
                                                            {90, 90, 90},
                                                            {220, 0, 120}}};
  const std::array<imaging::Marker, 4> markers{imaging::Marker::kCircle, imaging::Marker::kSquare,
                                               imaging::Marker::kTriangle,
                                               imaging::Marker::kDiamond};
  for (std::size_t s = 0; s < curves.series_names.size(); ++s) {
    imaging::PlotSeries series;
    series.rgb = palette[s % palette.size()];
    series.marker = markers[s % markers.size()];
    series.dashed = s >= palette.size();
    series.line = true;
    series.label = curves.series_names[s];
    for (const TradePoint& p : curves.points) {
      if (p.series == int(s)) series.x.push_back(p.time_ms), series.y.push_back(p.error);
    }
    panel.series.push_back(series);
  }
  imaging::PlotFigure figure;
  figure.panels = {panel};
  figure.footer = {
      "error: mean over channels of |fitted / truth - 1| for σ_a and σ_s', averaged; "
      "a model-made capture is exact for its own model only; the Monte Carlo capture's truth is "
      "transport, "
      "to which the tabulated model is exact"};
  figure.width = 1100, figure.height = 700;
  imaging::write_plot(path, figure);
}

}  // namespace

int run_fit_bench(const FitBenchOptions& options, std::ostream& log) {
  if (options.repeats < 1) throw Error("--repeats: expected at least 1");
  // Scratch captures live in a temporary output folder that is never committed: files written
  // inside it appear at once (the command's transaction defers only the real outputs), and it is
  // removed on return, on an error and on SIGINT/SIGTERM.
  // TMPDIR naming a folder that is not there is the user's setting to fix, said in one line.
  std::error_code ec;
  const fs::path tmp = fs::temp_directory_path(ec);
  if (ec || !fs::is_directory(tmp, ec))
    throw Error("TMPDIR: " + std::string(std::getenv("TMPDIR") ? std::getenv("TMPDIR") : "") +
                ": not a folder lucent can write scratch captures into (set TMPDIR to one)");
  const AtomicOutputDir scratch_dir(tmp / ("lucent-bench-fit-" + std::to_string(::getpid())));
  const std::vector<BenchCase> cases = prepare_cases(options, scratch_dir.temporary(), log);

  std::ostringstream csv;
  const TradeCurves curves = sweep_settings(cases, options.repeats, csv, log);

  fs::create_directories(options.out_dir);
  write_file_atomically(options.out_dir / "fit_tradeoff.csv", csv.str());
  write_trade_plot(curves, options.out_dir / "fit_tradeoff.png");
  return curves.settings;
}

}  // namespace lucent::fit
