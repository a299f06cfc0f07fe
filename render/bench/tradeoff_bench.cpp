// `lucent bench tradeoff`: renders each scene with every technique over its knobs and measures
// each image against a converged CPU reference (tradeoff_bench.h). The report (CSV, plot,
// summary) is tradeoff_report.cpp's.
#include "lucent/render/tradeoff_bench.h"
#include "lucent/render/render_bench.h"
#include "lucent/render/technique.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <ostream>
#include <sstream>
#include <thread>

#include "lucent/core/error.h"
#include "lucent/materials/material.h"
#include "lucent/render/environment.h"
#include "lucent/render/gl_context.h"
#include "lucent/render/hierarchical_renderer.h"
#include "lucent/render/image_compare.h"
#include "lucent/render/path_tracer.h"
#include "lucent/render/radiance_maps.h"
#include "lucent/render/reference_renderer.h"
#include "lucent/render/scene.h"
#include "lucent/render/sh_renderer.h"

namespace lucent::render {

void write_tradeoff_report(const std::vector<TradeoffRow>& rows, const std::string& machine,
                           const std::string& truth, int reference_samples,
                           const std::filesystem::path& out_dir);  // tradeoff_report.cpp

namespace {

struct SceneSpec {
  std::string text, mesh, material, lighting;
  double size_mm = 100;
};

SceneSpec parse_scene(const std::string& text) {
  SceneSpec spec{text, "", "", "", 100};
  std::vector<std::string> parts;
  for (std::size_t start = 0;;) {
    const std::size_t slash = text.find('/', start);
    parts.push_back(text.substr(start, slash == std::string::npos ? slash : slash - start));
    if (slash == std::string::npos) break;
    start = slash + 1;
  }
  if (parts.size() != 3 && parts.size() != 4) {
    throw Error(
        "--scenes: expected MESH/MATERIAL/LIGHTING[/SIZE_MM] (e.g. sphere/marble/point/30), "
        "got '" +
        text + "'");
  }
  spec.mesh = parts[0];
  spec.material = parts[1];
  spec.lighting = parts[2];
  if (parts.size() == 4) {
    char* end = nullptr;
    spec.size_mm = std::strtod(parts[3].c_str(), &end);
    if (parts[3].empty() || *end != '\0' || !(spec.size_mm >= 1 && spec.size_mm <= 10000)) {
      throw Error("--scenes: '" + text + "': the size must be 1..10000 mm, got '" + parts[3] + "'");
    }
  }
  if (spec.lighting != "directional" && spec.lighting != "point" && spec.lighting != "env") {
    throw Error("--scenes: '" + text + "': lighting must be directional, point or env, got '" +
                spec.lighting + "'");
  }
  if (spec.mesh.empty() || spec.material.empty()) {
    throw Error("--scenes: '" + text + "': the mesh and the material must not be empty");
  }
  return spec;
}

// A clear sky over a dark ground with a small sun (linear radiance, relative): the bench's
// environment map, made here so that the map needs no downloaded file.
EnvironmentMap procedural_sky() {
  EnvironmentMap map;
  map.image = ImageRgb(128, 64);
  map.source = "procedural sky (bench)";
  const Vec3f sun = Vec3f(0.45f, 0.75f, 0.5f).normalized();
  for (int y = 0; y < map.image.height; ++y) {
    for (int x = 0; x < map.image.width; ++x) {
      const Vec3f d = latlong_direction((x + 0.5f) / map.image.width,
                                        (y + 0.5f) / map.image.height);
      Vec3f c = d.y() > 0 ? Vec3f(0.25f, 0.35f, 0.6f) * (0.4f + 0.6f * d.y())
                          : Vec3f(0.08f, 0.07f, 0.06f);
      if (d.dot(sun) > std::cos(0.12f)) c += Vec3f(40.0f, 38.0f, 34.0f);
      for (int k = 0; k < 3; ++k) map.image.at(x, y, k) = c[k];
    }
  }
  return map;
}

Scene make_scene(const SceneSpec& spec, const std::string& mesh, const TradeoffBenchOptions& o) {
  Scene scene;
  scene.material = materials::load_material(spec.material);
  scene.mesh = load_mesh(mesh, spec.size_mm);
  scene.specular = false;  // the subsurface term alone: the lobe is the same in every technique
  scene.single_scattering = true;  // as the CLI renders by default (techniques without it: none)
  scene.angular = true;
  scene.geometry_factor = true;
  if (spec.lighting == "directional") {
    scene.lights = {parse_light("directional:1,0.5,0.5:1,1,1")};
  } else if (spec.lighting == "point") {
    scene.lights = {parse_light("point:-60,60,80:5000,5000,5000")};
  } else {
    scene.lights = environment_lights(procedural_sky(), o.env_lights, 1);
  }
  scene.camera = orbit_camera(scene.mesh, 30, 20, 3.4f, o.size, o.size);
  return scene;
}

double pass(const RenderStats& stats, const std::string& name) {
  for (const auto& [n, ms] : stats.pass_ms) {
    if (n == name) return ms;
  }
  return 0;
}

// A coarser (and, for the sphere, a finer) tessellation of the same shape, for the hierarchical
// technique's mesh-resolution knob; empty where there is none.
std::vector<std::string> other_resolutions(const std::string& mesh, bool finer) {
  if (mesh == "sphere") return finer ? std::vector<std::string>{"sphere:3", "sphere:5"}
                                     : std::vector<std::string>{"sphere:3"};
  if (mesh.rfind("dragon:", 0) == 0 && mesh.size() == 8 && mesh[7] >= '1' && mesh[7] <= '3') {
    return {std::string("dragon:") + char(mesh[7] + 1)};
  }
  return {};
}

class SceneBench {
 public:
  SceneBench(const SceneSpec& spec, const TradeoffBenchOptions& options, bool full,
             std::ostream& log, std::vector<TradeoffRow>& rows, std::string& device)
      : spec_(spec), options_(options), full_(full), log_(log), rows_(rows), device_(device),
        scene_(make_scene(spec, spec.mesh, options)) {}

  void run() {
    const TradeoffSweep sweep = full_ ? TradeoffSweep::kFull
                                : options_.sweep == TradeoffSweep::kTiny ? TradeoffSweep::kTiny
                                                                         : TradeoffSweep::kShort;
    run_reference_sweep(sweep);
    run_maps_sweep(sweep);
    run_sh_sweep(sweep);
    run_hierarchical_sweep(sweep);
  }

 private:
  // The truth every row is held to: the path tracer's image (one for every model) or the
  // converged reference of the row's model.
  const ImageRgb& reference(DiffusionModel model) {
    if (options_.truth == TradeoffTruth::kPathtrace) model = DiffusionModel::kTabulated;  // one key
    auto it = references_.find(model);
    if (it != references_.end()) return it->second;
    if (options_.truth == TradeoffTruth::kPathtrace) {
      PathTraceOptions p;
      p.pixel_samples = options_.truth_samples;
      p.seed = 1;
      p.threads = options_.threads;
      PathTraceImage image = render_pathtrace(scene_, p);
      log_ << "  " << spec_.text << ": path-traced truth (" << p.pixel_samples
           << " paths per pixel) in " << image.stats.total_ms / 1000 << " s\n";
      mask_ = nonzero_mask(image.image);
      // The truth's own noise relative to its mean, in compare_images's units: what every row's
      // relative RMSE holds beside its own error (taken out in quadrature in row()).
      double se2 = 0, sum = 0;
      std::size_t n = 0;
      for (int y = 0; y < image.image.height; ++y)
        for (int x = 0; x < image.image.width; ++x) {
          if (!mask_[std::size_t(y) * std::size_t(image.image.width) + std::size_t(x)]) continue;
          for (int c = 0; c < 3; ++c) {
            se2 += double(image.standard_error.at(x, y, c)) * image.standard_error.at(x, y, c);
            sum += image.image.at(x, y, c);
            ++n;
          }
        }
      truth_noise_ = n > 0 && sum > 0 ? std::sqrt(se2 / double(n)) / (sum / double(n)) : 0.0;
      log_ << "  " << spec_.text << ": the truth's own noise " << truth_noise_
           << " of its mean per pixel (taken out of every row's RMSE in quadrature)\n";
      return references_.emplace(model, std::move(image.image)).first->second;
    }
    ReferenceOptions r;
    r.pixel_samples = options_.reference_samples;
    r.seed = 1;
    r.threads = options_.threads;
    ReferenceImage image = render_reference(scene_, model, r);
    log_ << "  " << spec_.text << ": converged reference (" << materials::to_string(model) << ", "
         << r.pixel_samples << " probes per pixel) in " << image.stats.total_ms / 1000 << " s\n";
    mask_ = nonzero_mask(image.image);
    return references_.emplace(model, std::move(image.image)).first->second;
  }

  TradeoffRow row(const std::string& technique, DiffusionModel model, const std::string& setting,
                  const ImageRgb& image, const Mesh& mesh) {
    const ImageRgb& ref = reference(model);
    const ImageDifference d = compare_images(image, ref, mask_);
    TradeoffRow r;
    r.scene = spec_.text, r.mesh = mesh.name, r.material = spec_.material;
    r.lighting = spec_.lighting, r.technique = technique;
    r.model = materials::to_string(model), r.setting = setting;
    r.triangles = long(mesh.triangles.size());
    // Against the path tracer, less its own noise in quadrature (the rows' error, not the truth's).
    r.relative_rmse =
        std::sqrt(std::max(d.relative_rmse * d.relative_rmse - truth_noise_ * truth_noise_, 0.0));
    for (int c = 0; c < 3; ++c) r.mean_ratio[c] = d.mean_ratio[c];
    try {
      const ScaledComparison s = compare_scaled(image, ref, mask_);
      r.scaled_rmse = s.relative_rmse, r.scale = s.scale, r.correlation = s.correlation;
    } catch (const Error&) {  // an image black on the whole object: no scale fits it
      r.scaled_rmse = 1, r.scale = 0, r.correlation = 0;
    }
    return r;
  }

  void add(TradeoffRow r) {
    log_ << "  " << r.scene << " " << r.technique << " " << r.model << " " << r.setting
         << ": error " << r.error() << ", " << r.frame_ms << " ms per frame, " << r.image_ms
         << " ms to the image\n";
    rows_.push_back(std::move(r));
  }

  void run_reference_sweep(TradeoffSweep sweep) {
    const std::vector<int> samples = sweep == TradeoffSweep::kFull ? std::vector<int>{256, 1024, 4096}
                                     : sweep == TradeoffSweep::kShort ? std::vector<int>{1024}
                                                                      : std::vector<int>{64};
    for (int n : samples) {
      if (n >= options_.reference_samples) continue;
      ReferenceOptions r;
      r.pixel_samples = n;
      r.seed = 2;  // independent of the converged one
      r.threads = options_.threads;
      const DiffusionModel model = DiffusionModel::kDipole;
      ReferenceImage image = render_reference(scene_, model, r);
      TradeoffRow out = row(technique_info(TechniqueId::kReference).name, model,
                            "samples " + std::to_string(n), image.image, scene_.mesh);
      out.frame_ms = out.image_ms = out.converge_ms = image.stats.total_ms;
      add(std::move(out));
    }
  }

  struct MapsSetting {
    std::string name;
    int directions, map_size, samples, disc_points, frames;
    DiffusionModel model = DiffusionModel::kDipole;
  };

  void run_maps(const MapsSetting& m) {
    RenderSettings settings;
    settings.model = m.model;
    settings.directions = m.directions;
    settings.radiance_map_size = settings.light_map_size = m.map_size;
    settings.samples = m.samples;
    settings.disc_points = m.disc_points;
    settings.frames = m.frames;
    settings.validate();
    RadianceMapOptions options;
    std::vector<std::pair<int, ImageRgb>> snapshots;
    for (int t = 1; t <= m.frames; t *= 2) options.snapshot_frames.push_back(t);
    if (options.snapshot_frames.back() != m.frames) options.snapshot_frames.push_back(m.frames);
    options.on_snapshot = [&](int t, const ImageRgb& image) { snapshots.emplace_back(t, image); };
    RenderStats stats;
    render_radiance_maps(scene_, settings, options, &stats, nullptr);
    device_ = stats.details.value("gl_renderer", device_);
    const double setup = pass(stats, "setup");
    const double frame = pass(stats, "light map") + pass(stats, "radiance map") +
                         pass(stats, "mip blur") + pass(stats, "final");
    // The first snapshot within 2% relative RMSE of the last image.
    const ImageRgb& last = snapshots.back().second;
    int converged = m.frames;
    for (const auto& [t, image] : snapshots) {
      if (compare_images(image, last, mask_.empty() ? nonzero_mask(last) : mask_).relative_rmse <
          0.02) {
        converged = t;
        break;
      }
    }
    const std::string knobs = "K " + std::to_string(m.directions) + " W " +
                              std::to_string(m.map_size) + " N " + std::to_string(m.samples) +
                              " M " + std::to_string(m.disc_points);
    for (const auto& [t, image] : snapshots) {
      TradeoffRow r =
          row(technique_info(TechniqueId::kMaps).name, m.model,
              m.name + ": " + knobs + ", frame " + std::to_string(t), image, scene_.mesh);
      r.frames = t;
      r.frame_ms = frame;
      r.image_ms = setup + t * frame;
      r.converge_ms = setup + converged * frame;
      add(std::move(r));
    }
  }

  void run_maps_sweep(TradeoffSweep sweep) {
    reference(DiffusionModel::kDipole);  // the mask for the convergence test
    std::vector<MapsSetting> settings;
    const MapsSetting light{"light", 8, 256, 32, 256, 16};
    const MapsSetting fast{"fast", 4, 128, 8, 64, 16};
    if (sweep == TradeoffSweep::kTiny) {
      settings = {{"tiny", 4, 64, 8, 64, 2}};
    } else if (sweep == TradeoffSweep::kShort) {
      settings = {fast, light};
    } else {
      settings = {fast, light};
      auto vary = [&](const std::string& name, auto change) {
        MapsSetting s = light;
        s.name = name;
        change(s);
        settings.push_back(s);
      };
      vary("K 4", [](MapsSetting& s) { s.directions = 4; });
      vary("K 16", [](MapsSetting& s) { s.directions = 16; });
      vary("W 128", [](MapsSetting& s) { s.map_size = 128; });
      vary("W 512", [](MapsSetting& s) { s.map_size = 512; });
      vary("N 8", [](MapsSetting& s) { s.samples = 8; });
      vary("N 16", [](MapsSetting& s) { s.samples = 16; });
      vary("N 50", [](MapsSetting& s) { s.samples = 50; });
      vary("light ddipole", [](MapsSetting& s) { s.model = DiffusionModel::kDirectionalDipole; });
      vary("light tabulated", [](MapsSetting& s) { s.model = DiffusionModel::kTabulated; });
      // The defaults (Dal Corso's K 16, W 512, N 50, M 1000), 8 frames: 14 s a frame on llvmpipe.
      settings.push_back({"default", 16, 512, 50, 1000, 8});
    }
    for (const MapsSetting& s : settings) run_maps(s);
  }

  void run_sh_sweep(TradeoffSweep sweep) {
    std::vector<std::pair<int, int>> sizes;  // cube map, shadow map
    if (sweep == TradeoffSweep::kTiny) {
      sizes = {{16, 128}};
    } else if (sweep == TradeoffSweep::kShort) {
      sizes = {{16, 256}, {64, 512}};
    } else {
      sizes = {{16, 512}, {32, 512}, {64, 512}, {128, 512}, {64, 128}, {64, 256}, {64, 1024}};
    }
    for (const auto& [cube, shadow] : sizes) {
      ShOptions o;
      o.cube_map_size = cube;
      o.shadow_map_size = shadow;
      o.validate();
      RenderStats stats;
      const ImageRgb image = render_sh(scene_, o, &stats);
      TradeoffRow r = row(technique_info(TechniqueId::kSh).name, DiffusionModel::kDipole,
                          "cube " + std::to_string(cube) + " shadow " + std::to_string(shadow),
                          image, scene_.mesh);
      r.frame_ms = stats.details.value("frame_ms", 0.0);
      r.image_ms = r.converge_ms = pass(stats, "setup") + r.frame_ms;
      add(std::move(r));
    }
  }

  // Two frames: the first builds the hierarchy and the links (and compiles the programs), the
  // second is the steady state of the render mode (links kept, the solve and the draw redone).
  void run_hierarchical(const std::string& name, const hierarchical::Options& o,
                        const Scene& scene) {
    o.validate();
    const auto context = GlContext::create_headless();
    HierarchicalRenderer renderer;
    const auto start = std::chrono::steady_clock::now();
    renderer.setup(scene, o);
    renderer.render_frame();
    (void)renderer.read_image();
    const double first_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    renderer.render_frame();
    const ImageRgb image = renderer.read_image();
    const hierarchical::Stats& s = renderer.stats();
    TradeoffRow r = row(technique_info(TechniqueId::kHierarchical).name, DiffusionModel::kDipole,
                        name, image, scene.mesh);
    r.frame_ms = s.irradiance_ms + s.pull_ms + s.gather_ms + s.push_ms + renderer.upload_ms() +
                 renderer.draw_ms();
    r.image_ms = r.converge_ms = first_ms;
    add(std::move(r));
  }

  void run_hierarchical_sweep(TradeoffSweep sweep) {
    const hierarchical::Options base;
    auto named = [](const hierarchical::Options& o) {
      std::ostringstream s;
      s << "eps1 " << o.epsilon_1 << " eps2 " << o.epsilon_2 << " c " << o.form_factor.edge_constant;
      return s.str();
    };
    std::vector<hierarchical::Options> variants;
    hierarchical::Options coarse = base;
    coarse.epsilon_1 = 0.2, coarse.epsilon_2 = 1.6;
    if (sweep == TradeoffSweep::kTiny) {
      variants = {coarse};
    } else if (sweep == TradeoffSweep::kShort) {
      variants = {coarse, base};
    } else {
      variants = {coarse, base};
      for (double e1 : {0.2, 0.1, 0.025}) {
        hierarchical::Options o = base;
        o.epsilon_1 = e1;
        variants.push_back(o);
      }
      for (double e2 : {1.6, 0.8, 0.2}) {
        hierarchical::Options o = base;
        o.epsilon_2 = e2;
        variants.push_back(o);
      }
      for (double c : {0.8, 0.2}) {
        hierarchical::Options o = base;
        o.form_factor.edge_constant = c;
        variants.push_back(o);
      }
    }
    for (const hierarchical::Options& o : variants) run_hierarchical(named(o), o, scene_);
    if (sweep == TradeoffSweep::kTiny) return;
    // The mesh's resolution (the same shape; the reference stays on the scene's mesh).
    for (const std::string& mesh : other_resolutions(spec_.mesh, sweep == TradeoffSweep::kFull)) {
      const Scene other = make_scene(spec_, mesh, options_);
      run_hierarchical(named(base) + ", mesh " + mesh, base, other);
    }
  }

  const SceneSpec spec_;
  const TradeoffBenchOptions& options_;
  const bool full_;
  std::ostream& log_;
  std::vector<TradeoffRow>& rows_;
  std::string& device_;
  const Scene scene_;
  std::map<DiffusionModel, ImageRgb> references_;
  std::vector<std::uint8_t> mask_;
  double truth_noise_ = 0;  // the path-traced truth's relative noise per pixel; 0 for the reference
};

}  // namespace

// "CPU model, N threads; OpenGL renderer" for the report.
std::string machine_description(const std::string& gl_renderer) {
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line, cpu = "unknown CPU";
  while (std::getline(cpuinfo, line)) {
    if (line.rfind("model name", 0) == 0) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  }
  return cpu + ", " + std::to_string(std::thread::hardware_concurrency()) +
         " hardware threads; OpenGL: " + gl_renderer;
}

TradeoffSweep parse_tradeoff_sweep(const std::string& text) {
  if (text == "full") return TradeoffSweep::kFull;
  if (text == "short") return TradeoffSweep::kShort;
  if (text == "tiny") return TradeoffSweep::kTiny;
  throw Error("--sweep: expected full, short or tiny, got '" + text + "'");
}

TradeoffTruth parse_tradeoff_truth(const std::string& text) {
  if (text == "pathtrace") return TradeoffTruth::kPathtrace;
  if (text == "reference") return TradeoffTruth::kReference;
  throw Error("--truth: expected pathtrace or reference, got '" + text + "'");
}

double TradeoffRow::error() const { return scale_only() ? scaled_rmse : relative_rmse; }

bool TradeoffRow::scale_only() const {
  const TechniqueInfo* t = find_technique(technique);
  return t != nullptr && !t->physically_based;
}

std::vector<TradeoffRow> run_tradeoff_bench(const TradeoffBenchOptions& options,
                                            std::ostream& log) {
  if (options.scenes.empty()) throw Error("--scenes: give at least one scene");
  if (options.size < 8 || options.size > 1024) {
    throw Error("--size: expected 8..1024 pixels, got " + std::to_string(options.size));
  }
  if (options.truth_samples < 16) {
    throw Error("--truth-samples: expected at least 16 paths per pixel, got " +
                std::to_string(options.truth_samples));
  }
  if (options.reference_samples < 16) {
    throw Error("--reference-samples: expected at least 16 probes per pixel, got " +
                std::to_string(options.reference_samples));
  }
  if (options.env_lights < 1 || options.env_lights > 256) {
    throw Error("--env-lights: expected 1..256, got " + std::to_string(options.env_lights));
  }
  std::vector<SceneSpec> specs;
  for (const std::string& text : options.scenes) specs.push_back(parse_scene(text));
  for (const SceneSpec& s : specs) materials::load_material(s.material);  // fail before any work
  std::vector<TradeoffRow> rows;
  std::string device = "unknown";
  for (std::size_t i = 0; i < specs.size(); ++i) {
    log << "bench tradeoff: scene " << i + 1 << "/" << specs.size() << ": " << specs[i].text
        << "\n";
    SceneBench(specs[i], options, i == 0 && options.sweep == TradeoffSweep::kFull, log, rows,
               device)
        .run();
  }
  const std::string truth =
      options.truth == TradeoffTruth::kPathtrace
          ? "the path-traced truth (--technique pathtrace, " +
                std::to_string(options.truth_samples) +
                " paths per pixel: the medium itself, so the error includes each model's; its own "
                "per-pixel noise, from its standard errors, taken out of every RMSE in "
                "quadrature); every technique with its single scattering, angular and shape "
                "factors "
                "where it has them"
          : "a converged CPU reference of " + std::to_string(options.reference_samples) +
                " probes per pixel, same scene and model";
  write_tradeoff_report(rows, machine_description(device), truth,
                        options.truth == TradeoffTruth::kReference ? options.reference_samples : 0,
                        options.out_dir);
  return rows;
}

}  // namespace lucent::render
