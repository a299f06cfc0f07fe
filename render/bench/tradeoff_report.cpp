// The trade-off map's report (tradeoff_bench.h): the CSV, the Pareto fronts, the times relative to
// the radiance maps at equal error, and the error-against-time figure.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>

#include "lucent/core/atomic_file.h"
#include "lucent/imaging/plot.h"
#include "lucent/render/technique.h"
#include "lucent/render/tradeoff_bench.h"

namespace lucent::render {
namespace {

double time_of(const TradeoffRow& r, bool use_frame_time) {
  return use_frame_time ? r.frame_ms : r.image_ms;
}

std::string csv_text(const std::string& s) {
  if (s.find_first_of(",\"") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string number(double v, int digits = 4) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*g", digits, v);
  return buffer;
}

std::string milliseconds(double ms) {
  char buffer[64];
  if (ms >= 10000) {
    std::snprintf(buffer, sizeof buffer, "%.1f s", ms / 1000);
  } else if (ms >= 10) {
    std::snprintf(buffer, sizeof buffer, "%.0f ms", ms);
  } else {
    std::snprintf(buffer, sizeof buffer, "%.2g ms", ms);
  }
  return buffer;
}

std::vector<std::string> scenes_of(const std::vector<TradeoffRow>& rows) {
  std::vector<std::string> scenes;
  for (const TradeoffRow& r : rows) {
    if (std::find(scenes.begin(), scenes.end(), r.scene) == scenes.end()) scenes.push_back(r.scene);
  }
  return scenes;
}

std::vector<TradeoffRow> of_scene(const std::vector<TradeoffRow>& rows, const std::string& scene) {
  std::vector<TradeoffRow> out;
  for (const TradeoffRow& r : rows) {
    if (r.scene == scene) out.push_back(r);
  }
  return out;
}

// The techniques the sweep runs, in the map's order (fur has no scene of its own in the sweep).
const TechniqueId kTechniques[] = {TechniqueId::kMaps, TechniqueId::kHierarchical, TechniqueId::kSh,
                                   TechniqueId::kReference};

bool is(const TradeoffRow& r, TechniqueId id) {
  return r.technique == technique_info(id).name;
}

// The equal-error comparison of one row with the maps' front, in words for the summary.
std::string against_maps(const TradeoffRow& r, const std::vector<TradeoffRow>& maps_front,
                         bool use_frame_time) {
  if (r.scale_only()) return "none (right only up to a scale)";
  if (maps_front.empty()) return "no maps rows";
  const double t = maps_time_at_error(maps_front, r.error(), use_frame_time);
  if (t > 0) return number(time_of(r, use_frame_time) / t, 3) + "x";
  if (r.error() > maps_front.front().error()) {
    return "none: the maps do better (" + number(maps_front.front().error(), 3) + ") already at " +
           milliseconds(time_of(maps_front.front(), use_frame_time));
  }
  return "none: the maps never reach it (best " + number(maps_front.back().error(), 3) + ")";
}

}  // namespace

std::vector<TradeoffRow> pareto_front(const std::vector<TradeoffRow>& rows,
                                      const std::string& technique, bool use_frame_time) {
  std::vector<TradeoffRow> candidates;
  for (const TradeoffRow& r : rows) {
    if ((technique.empty() || r.technique == technique) && std::isfinite(r.error()) &&
        time_of(r, use_frame_time) > 0) {
      candidates.push_back(r);
    }
  }
  std::sort(candidates.begin(), candidates.end(), [&](const TradeoffRow& a, const TradeoffRow& b) {
    const double ta = time_of(a, use_frame_time), tb = time_of(b, use_frame_time);
    return ta != tb ? ta < tb : a.error() < b.error();
  });
  std::vector<TradeoffRow> front;
  for (const TradeoffRow& r : candidates) {
    if (front.empty() || r.error() < front.back().error()) front.push_back(r);
  }
  return front;
}

double maps_time_at_error(const std::vector<TradeoffRow>& maps_front, double error,
                          bool use_frame_time) {
  if (maps_front.empty() || !(error > 0)) return -1;
  // The front's errors fall as its times grow: find the two points around `error`.
  for (std::size_t i = 0; i < maps_front.size(); ++i) {
    const double e = maps_front[i].error();
    if (e == error) return time_of(maps_front[i], use_frame_time);
    if (e < error) {
      if (i == 0) return -1;  // faster than the fastest: not measured, not extrapolated
      const double e0 = std::log(maps_front[i - 1].error()), e1 = std::log(e);
      const double t0 = std::log(time_of(maps_front[i - 1], use_frame_time));
      const double t1 = std::log(time_of(maps_front[i], use_frame_time));
      const double w = (std::log(error) - e0) / (e1 - e0);
      return std::exp(t0 + w * (t1 - t0));
    }
  }
  return -1;  // more accurate than the maps' best
}

std::string tradeoff_csv(const std::vector<TradeoffRow>& rows) {
  std::ostringstream csv;
  csv << "scene,mesh,triangles,material,lighting,technique,model,setting,frames,frame_ms,image_ms,"
         "converge_ms,relative_rmse,mean_ratio_r,mean_ratio_g,mean_ratio_b,scaled_rmse,scale,"
         "correlation,error\n";
  for (const TradeoffRow& r : rows) {
    csv << csv_text(r.scene) << ',' << csv_text(r.mesh) << ',' << r.triangles << ','
        << csv_text(r.material) << ',' << r.lighting << ',' << r.technique << ',' << r.model << ','
        << csv_text(r.setting) << ',' << r.frames << ',' << number(r.frame_ms, 6) << ','
        << number(r.image_ms, 6) << ',' << number(r.converge_ms, 6) << ','
        << number(r.relative_rmse, 5) << ',' << number(r.mean_ratio[0], 5) << ','
        << number(r.mean_ratio[1], 5) << ',' << number(r.mean_ratio[2], 5) << ','
        << number(r.scaled_rmse, 5) << ',' << number(r.scale, 5) << ','
        << number(r.correlation, 5) << ',' << number(r.error(), 5) << '\n';
  }
  return csv.str();
}

std::string tradeoff_summary(const std::vector<TradeoffRow>& rows, const std::string& machine,
                             const std::string& truth, int reference_samples) {
  std::ostringstream md;
  md << "# The speed/accuracy map: summary\n\n"
     << "Written by `lucent bench tradeoff` from tradeoff.csv (read the README beside it for "
        "which technique to pick when). Machine: "
     << machine << ". Error: relative RMSE over the object's pixels against " << truth
     << " (sh: after the least-squares scale, since it "
        "is right only up to one). Time to the image: from nothing to that image (setup, "
        "precomputation such as the hierarchy's links, every accumulated frame), GL context "
        "creation excluded; time per frame: the steady-state cost of one more frame (the "
        "reference: the whole render).\n";
  for (const std::string& scene : scenes_of(rows)) {
    const std::vector<TradeoffRow> here = of_scene(rows, scene);
    md << "\n## " << scene << " (" << here.front().triangles << " triangles)\n\n";
    // The converged reference's own noise, from the independent reference runs:
    // e^2 = s^2 / n + s^2 / N  ->  its noise s / sqrt(N) = e / sqrt(N / n + 1).
    for (const TradeoffRow& r : here) {
      int n = 0;
      if (reference_samples > 0 && is(r, TechniqueId::kReference) &&
          std::sscanf(r.setting.c_str(), "samples %d", &n) == 1 && n > 0) {
        md << "- reference at " << n << " probes: " << number(r.relative_rmse, 3)
           << " from the converged one, so the converged reference's own noise is about "
           << number(r.relative_rmse / std::sqrt(double(reference_samples) / n + 1), 2) << "\n";
      }
    }
    for (const bool per_frame : {false, true}) {
      const std::vector<TradeoffRow> front = pareto_front(here, "", per_frame);
      md << "\nPareto front over every technique, error against "
         << (per_frame ? "time per frame" : "time to the image") << ":\n\n"
         << "| technique | model | setting | " << (per_frame ? "per frame" : "to the image")
         << " | error |\n| --- | --- | --- | --- | --- |\n";
      for (const TradeoffRow& r : front) {
        md << "| " << r.technique << " | " << r.model << " | " << r.setting << " | "
           << milliseconds(time_of(r, per_frame)) << " | " << number(r.error(), 3) << " |\n";
      }
    }
    const std::string& maps = technique_info(TechniqueId::kMaps).name;
    const std::vector<TradeoffRow> maps_image = pareto_front(here, maps, false);
    const std::vector<TradeoffRow> maps_frame = pareto_front(here, maps, true);
    md << "\nEach technique's own front (time to the image), and its time relative to the maps "
          "at the same error (log-log interpolation along the maps' front; none where the maps' "
          "measured range does not reach that error):\n\n"
       << "| technique | setting | to the image | per frame | error | correlation | time / maps "
          "(image) | time / maps (frame) |\n| --- | --- | --- | --- | --- | --- | --- | --- |\n";
    for (const TechniqueId technique : kTechniques) {
      for (const TradeoffRow& r : pareto_front(here, technique_info(technique).name, false)) {
        md << "| " << r.technique << " | " << r.setting << " | " << milliseconds(r.image_ms)
           << " | " << milliseconds(r.frame_ms) << " | " << number(r.error(), 3)
           << (r.scale_only() ? " (scaled; unscaled " + number(r.relative_rmse, 3) + ")" : "")
           << " | " << number(r.correlation, 3) << " | "
           << (is(r, TechniqueId::kMaps) ? "1" : against_maps(r, maps_image, false)) << " | "
           << (is(r, TechniqueId::kMaps) ? "1" : against_maps(r, maps_frame, true)) << " |\n";
      }
    }
  }
  return md.str();
}

void write_tradeoff_report(const std::vector<TradeoffRow>& rows, const std::string& machine,
                           const std::string& truth, int reference_samples,
                           const std::filesystem::path& out_dir) {
  std::filesystem::create_directories(out_dir);
  write_file_atomically(out_dir / "tradeoff.csv", tradeoff_csv(rows));
  write_file_atomically(out_dir / "tradeoff_summary.md",
                        tradeoff_summary(rows, machine, truth, reference_samples));
  const std::array<std::array<std::uint8_t, 3>, 4> colours{
      {{30, 70, 200}, {20, 150, 40}, {220, 120, 0}, {60, 60, 60}}};
  const std::array<imaging::Marker, 4> markers{imaging::Marker::kCircle, imaging::Marker::kSquare,
                                               imaging::Marker::kTriangle,
                                               imaging::Marker::kDiamond};
  auto panel_for = [&](const std::string& scene, bool per_frame) {
    const std::vector<TradeoffRow> here = of_scene(rows, scene);
    imaging::PlotPanel panel;
    panel.title = scene + ": error against " +
                  (per_frame ? std::string("time per frame") : std::string("time to the image")) +
                  " (lines: each technique's Pareto front)";
    panel.x_label = per_frame ? "time per frame (ms)" : "time to the image (ms)";
    panel.y_label = "relative RMSE vs the truth";
    panel.log_x = panel.log_y = true;
    for (std::size_t k = 0; k < std::size(kTechniques); ++k) {
      const TechniqueInfo& info = technique_info(kTechniques[k]);
      const std::string& technique = info.name;
      imaging::PlotSeries points, front;
      points.rgb = front.rgb = colours[k];
      points.marker = markers[k];
      points.label = info.physically_based ? technique : technique + " (after the best scale)";
      for (const TradeoffRow& r : here) {
        if (r.technique != technique) continue;
        points.x.push_back(time_of(r, per_frame));
        points.y.push_back(r.error());
      }
      if (points.x.empty()) continue;
      front.markers = false;
      front.line = true;
      for (const TradeoffRow& r : pareto_front(here, technique, per_frame)) {
        front.x.push_back(time_of(r, per_frame));
        front.y.push_back(r.error());
      }
      panel.series.push_back(points);
      panel.series.push_back(front);
    }
    return panel;
  };
  imaging::PlotFigure figure;
  const std::vector<std::string> scenes = scenes_of(rows);
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    figure.panels.push_back(panel_for(scenes[i], false));
    if (i == 0) figure.panels.push_back(panel_for(scenes[i], true));
  }
  figure.footer = {"Machine: " + machine +
                   ". Subsurface term only, objects of 100 mm unless the scene gives a size; maps: "
                   "frames accumulate along each "
                   "setting's points; the reference: independent runs at fewer probes."};
  figure.width = 1000;
  figure.height = 160 + 420 * int(figure.panels.size());
  imaging::write_plot(out_dir / "tradeoff.png", figure);
  imaging::write_plot(out_dir / "tradeoff.svg", figure);
}

}  // namespace lucent::render
