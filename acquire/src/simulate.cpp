#include "lucent/acquire/simulate.h"
#include "lucent/core/json_file.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/imaging/image_io.h"
#include "lucent/materials/dipole.h"
#include "lucent/materials/directional_dipole.h"
#include "lucent/materials/fresnel.h"
#include "lucent/version.h"

namespace lucent::acquire {
namespace {

using nlohmann::json;

imaging::ImageRgb to_image(const PhotonTransportResult& result, bool standard_error) {
  const int size = result.options.size;
  imaging::ImageRgb image(size, size);
  for (int c = 0; c < 3; ++c) {
    const auto& ch = result.channels[c];
    const std::vector<double>& values = standard_error ? ch.image_standard_error : ch.image;
    if (values.empty()) continue;
    for (int j = 0; j < size; ++j) {
      for (int i = 0; i < size; ++i) image.at(i, j, c) = float(values[std::size_t(j) * size + i]);
    }
  }
  return image;
}

double peak(const imaging::ImageRgb& image) {
  double m = 0;
  for (float v : image.data) m = std::max(m, double(v));
  return m;
}

json transport_to_json(const PhotonTransportOptions& o) {
  return {
      {"thickness_mm", std::isfinite(o.thickness_mm) ? json(o.thickness_mm) : json("infinite")},
      {"side", o.far_side ? "transmitted" : "reflected"},
      {"beam_sigma_mm", o.beam_sigma_mm},
      {"incidence_deg", o.incidence_deg},
      {"azimuth_deg", o.azimuth_deg},
      {"photons_per_channel", o.photons},
      {"seed", o.seed},
      {"max_radius_mm", o.max_radius_mm},
      {"size_px", o.size},
      {"pixel_mm", o.pixel_mm},
      {"view_deg", o.view_deg},
      {"view_azimuth_deg", o.view_azimuth_deg},
      {"boundary_scoring", o.boundary_scoring == BoundaryScoring::kSplit ? "split" : "stochastic"}};
}

json camera_to_json(const CameraOptions& o, double scale) {
  return {{"exposures_s", o.exposures_s},
          {"response", to_string(o.response)},
          {"bits", o.bits},
          {"full_well_e", o.full_well_e},
          {"read_noise_e", o.read_noise_e},
          {"black_level_e", o.black_level_e},
          {"noise", o.noise},
          {"electrons_per_radiance_s", scale},
          {"seed", o.seed}};
}

json totals_to_json(const PhotonTransportResult& r) {
  json totals = json::object();
  const auto put = [&](const char* name, auto member) {
    json values = json::array(), errors = json::array();
    for (const auto& ch : r.channels) {
      const Estimate& e = ch.*member;
      values.push_back(ch.photons ? json(e.value) : json(nullptr));
      errors.push_back(ch.photons ? json(e.standard_error) : json(nullptr));
    }
    totals[name] = values;
    totals[std::string(name) + "_se"] = errors;
  };
  put("diffuse_reflectance", &ChannelTransportResult::diffuse_reflectance);
  put("specular_reflectance", &ChannelTransportResult::specular_reflectance);
  put("transmittance", &ChannelTransportResult::transmittance);
  put("absorbed", &ChannelTransportResult::absorbed);
  return totals;
}

const char* extension(BracketFormat format) {
  return format == BracketFormat::kDng ? ".dng" : ".png";
}

std::string bracket_name(const char* stem, std::size_t k, BracketFormat format) {
  return std::string(stem) + "_" + std::to_string(k) + extension(format);
}

// One bracket in the chosen format; a DNG's capture entry leaves the exposure to its metadata.
Bracket write_bracket(const std::filesystem::path& dir, const std::string& name,
                      const imaging::ImageRgb& radiance, double t, double scale,
                      const CameraOptions& camera, std::uint64_t stream, BracketFormat format) {
  if (format == BracketFormat::kDng) {
    imaging::write_dng(dir / name, expose_mosaic(radiance, t, scale, camera, stream));
    return Bracket(name);
  }
  imaging::write_png(dir / name, expose(radiance, t, scale, camera, stream));
  return Bracket(name, t);
}

}  // namespace

imaging::ImageRgb model_radiance(const materials::Material& material, RadianceSource source,
                                 const PhotonTransportOptions& g) {
  constexpr double kDegree = std::numbers::pi / 180;
  const double theta = g.incidence_deg * kDegree, phi = g.azimuth_deg * kDegree;
  const materials::Vec3<double> w_i(-std::sin(theta) * std::cos(phi),
                                    -std::sin(theta) * std::sin(phi), std::cos(theta));
  const materials::Vec3<double> up(0, 0, 1);
  imaging::ImageRgb image(g.size, g.size);
  for (int c = 0; c < 3; ++c) {
    const materials::Medium<double> medium = material.medium(c);
    const double fresnel =
        materials::fresnel_transmittance(std::cos(theta), medium.eta) *
        materials::fresnel_transmittance(std::cos(g.view_deg * kDegree), medium.eta);
    const materials::StandardDipole<double> dipole(medium);
    const materials::DirectionalDipole<double> dd(medium);
    const auto S = [&](double x, double y) {
      if (source == RadianceSource::kDipole) return dipole.R_d(std::hypot(x, y)) / std::numbers::pi;
      return dd.S_d(materials::Vec3<double>::Zero(), up, w_i, {x, y, 0.0}, up);
    };
    for (int j = 0; j < g.size; ++j) {
      for (int i = 0; i < g.size; ++i) {
        const double x0 = (i - g.size / 2.0) * g.pixel_mm, y0 = (j - g.size / 2.0) * g.pixel_mm;
        // The profile is steepest at the entry point: more points in the pixels around it.
        const bool centre = std::abs(x0 + 0.5 * g.pixel_mm) < 1.5 * g.pixel_mm &&
                            std::abs(y0 + 0.5 * g.pixel_mm) < 1.5 * g.pixel_mm;
        const int n = centre ? 16 : 4;
        double sum = 0;
        for (int a = 0; a < n; ++a) {
          for (int b = 0; b < n; ++b)
            sum += S(x0 + (a + 0.5) / n * g.pixel_mm, y0 + (b + 0.5) / n * g.pixel_mm);
        }
        image.at(i, j, c) = float(fresnel * sum / (n * n));
      }
    }
  }
  return image;
}

imaging::ImageRgb white_reference_radiance(int size, double pixel_mm, double rho, double sigma_mm) {
  imaging::ImageRgb image(size, size);
  // The spot sits where the beam enters: the centre of the grid (x = y = 0 mm).
  const auto cdf = [&](double x) { return 0.5 * std::erfc(-x / (std::sqrt(2.0) * sigma_mm)); };
  const double area = pixel_mm * pixel_mm;
  for (int j = 0; j < size; ++j) {
    const double y0 = (j - size / 2.0) * pixel_mm;
    const double py = cdf(y0 + pixel_mm) - cdf(y0);
    for (int i = 0; i < size; ++i) {
      const double x0 = (i - size / 2.0) * pixel_mm;
      const double px = cdf(x0 + pixel_mm) - cdf(x0);
      const float L = float(rho / std::numbers::pi * px * py / area);
      for (int c = 0; c < 3; ++c) image.at(i, j, c) = L;
    }
  }
  return image;
}

namespace {

// Set-up: the transport the run simulates, with the material's media, imaged unless only the
// profile is wanted.
PhotonTransportOptions simulation_transport(const SimulateOptions& options) {
  PhotonTransportOptions transport = options.transport;
  for (int c = 0; c < 3; ++c) transport.media[c] = options.material.medium(c);
  transport.image = !options.profile_only;
  return transport;
}

// Set-up: the camera of the run, checked (when images are made) before the long simulation.
CameraOptions simulation_camera(const SimulateOptions& options,
                                const PhotonTransportOptions& transport) {
  // One seed drives every random choice: the camera's noise comes from the transport's seed, so
  // repeated captures with different --seed differ in their noise too. The same value is safe: the
  // camera's mt19937_64 streams and the transport's xoshiro streams mix it differently.
  CameraOptions camera = options.camera;
  camera.seed = transport.seed;
  if (!options.profile_only) validate_camera_options(camera);
  if (!options.profile_only && options.bracket_format == BracketFormat::kDng &&
      (camera.bits != 16 || camera.response != Response::kLinear)) {
    throw Error(
        "--bracket-format dng: a RAW sensor records linear 16-bit codes (use --bits 16 "
        "and --response linear)");
  }
  return camera;
}

// Truth: what the run simulated and, for the Monte Carlo source, its totals; the camera's part is
// added by write_camera_images.
json truth_record(const SimulateOptions& options, const PhotonTransportOptions& transport,
                  const PhotonTransportResult& result, bool monte_carlo) {
  json truth = {{"format", "lucent-simulation-truth"},
                {"version", 1},
                {"material", materials::material_to_json(options.material)},
                {"source", monte_carlo                                 ? "montecarlo"
                           : options.source == RadianceSource::kDipole ? "dipole"
                                                                       : "ddipole"},
                {"transport", transport_to_json(transport)},
                {"tool", std::string("lucent simulate ") + kVersion}};
  if (monte_carlo) {
    truth["totals"] = totals_to_json(result);
    truth["mean_interactions"] = json::array();
    for (const auto& ch : result.channels)
      truth["mean_interactions"].push_back(ch.mean_interactions);
    truth["wall_seconds"] = result.wall_seconds;
    truth["threads_used"] = result.threads_used;
  }
  return truth;
}

// Images: writes the brackets into the output folder in order, each with the next camera noise
// stream, and lists their names among the files written.
struct BracketWriter {
  const std::filesystem::path& dir;
  const CameraOptions& camera;
  double scale;
  BracketFormat format;
  std::vector<std::string>& files;
  std::uint64_t stream = 0;

  Bracket write(const std::string& name, const imaging::ImageRgb& radiance, double t) {
    Bracket bracket = write_bracket(dir, name, radiance, t, scale, camera, stream++, format);
    files.push_back(name);
    return bracket;
  }
};

// Images: the capture's geometry and response, as a rig would record them.
Capture capture_geometry(const SimulateOptions& options, const PhotonTransportOptions& transport,
                         const CameraOptions& camera) {
  Capture capture;
  capture.pixel_pitch_mm = transport.pixel_mm;
  capture.incidence_polar_deg = transport.incidence_deg;
  capture.incidence_azimuth_deg = transport.azimuth_deg;
  capture.view_deg = transport.view_deg;
  capture.ior = options.material.ior;
  if (std::isfinite(transport.thickness_mm)) capture.thickness_mm = transport.thickness_mm;
  capture.transmitted = transport.far_side;
  // At oblique incidence the light emerges ahead of the entry point, so the brightest region no
  // longer marks it; a real rig marks it (the specular glint, a fiducial). The simulator knows
  // it: the corner between the four middle pixels.
  if (transport.incidence_deg > 0) {
    capture.beam_point_px = std::array<double, 2>{transport.size / 2.0, transport.size / 2.0};
  }
  capture.response = camera.response;
  return capture;
}

// Images: the white reference's brackets, added to the capture; returns its truth record.
json write_white_reference(const SimulateOptions& options, const PhotonTransportOptions& transport,
                           const imaging::ImageRgb& radiance, BracketWriter& brackets,
                           Capture& capture) {
  const CameraOptions& camera = brackets.camera;
  const double sigma = options.white_spot_sigma_mm > 0 ? options.white_spot_sigma_mm
                       : transport.beam_sigma_mm > 0   ? transport.beam_sigma_mm
                                                       : transport.pixel_mm;
  // The same beam on the reference, seen through the same lens.
  const imaging::ImageRgb white =
      apply_lens(white_reference_radiance(transport.size, transport.pixel_mm,
                                          options.white_reflectance, sigma),
                 transport.pixel_mm, options.lens_blur_mm, options.glare, options.glare_radius_mm);
  // The reference is far brighter than the sample: shorten its exposures by a power of two so
  // that its peak, too, fills about auto_fill of the well at the shortest one.
  const double ratio = peak(white) / peak(radiance);
  const double shorten = std::max(1.0, std::exp2(std::ceil(std::log2(ratio))));
  WhiteReference reference;
  reference.reflectance = options.white_reflectance;
  for (std::size_t k = 0; k < camera.exposures_s.size(); ++k) {
    const double t = camera.exposures_s[k] / shorten;
    const std::string name = bracket_name("white", k, brackets.format);
    reference.images.images.push_back(brackets.write(name, white, t));
  }
  capture.white_reference = reference;
  return {{"reflectance", options.white_reflectance},
          {"spot_sigma_mm", sigma},
          {"exposure_divisor", shorten}};
}

// Images: the truth radiance, the sample's brackets, the white reference, the dark frame and
// capture.json; adds the camera's part of the truth record.
void write_camera_images(const SimulateOptions& options, const PhotonTransportOptions& transport,
                         const CameraOptions& camera, bool monte_carlo, const AtomicOutputDir& out,
                         SimulateSummary& summary, json& truth) {
  const PhotonTransportResult& result = summary.transport;
  const imaging::ImageRgb truth_radiance =
      monte_carlo ? to_image(result, false)
                  : model_radiance(options.material, options.source, transport);
  // What the camera sees: the sample's light through the lens.
  const imaging::ImageRgb radiance =
      apply_lens(truth_radiance, transport.pixel_mm, options.lens_blur_mm, options.glare,
                 options.glare_radius_mm);
  const double pixel_area = transport.pixel_mm * transport.pixel_mm;
  const double scale = camera_scale(camera, peak(radiance));
  summary.camera_scale = scale;
  imaging::write_exr(out.temporary() / "truth_radiance.exr", truth_radiance,
                     {{"units", "radiance per unit incident power, mm^-2 sr^-1"}});
  summary.files = {"truth_radiance.exr"};
  if (monte_carlo) {
    imaging::write_exr(out.temporary() / "truth_radiance_se.exr", to_image(result, true),
                       {{"units", "standard error of truth_radiance, mm^-2 sr^-1"}});
    summary.files.push_back("truth_radiance_se.exr");
  }

  Capture capture = capture_geometry(options, transport, camera);
  const BracketFormat format = options.bracket_format;
  BracketWriter brackets{out.temporary(), camera, scale, format, summary.files};
  for (std::size_t k = 0; k < camera.exposures_s.size(); ++k) {
    const double t = camera.exposures_s[k];
    const std::string name = bracket_name("bracket", k, format);
    capture.sample.images.push_back(brackets.write(name, radiance, t));
  }
  json white_json = nullptr;
  if (options.white_reference)
    white_json = write_white_reference(options, transport, radiance, brackets, capture);
  if (options.dark_frame) {
    const imaging::ImageRgb black(transport.size, transport.size, 0.0f);
    const std::string name = std::string("dark") + extension(format);
    brackets.write(name, black, camera.exposures_s.back());
    capture.dark = name;
  }
  capture.provenance = {{"tool", std::string("lucent simulate ") + kVersion},
                        {"material", options.material.name},
                        {"truth", "truth.json"}};
  write_capture(out.temporary() / "capture.json", capture);
  summary.files.push_back("capture.json");
  truth["camera"] = camera_to_json(camera, scale);
  truth["camera"]["bracket_format"] = format == BracketFormat::kDng ? "dng" : "png";
  truth["white_reference"] = white_json;
  truth["lens"] = {{"blur_mm", options.lens_blur_mm},
                   {"glare", options.glare},
                   {"glare_radius_mm", options.glare_radius_mm}};
  truth["pixel_area_mm2"] = pixel_area;
}

}  // namespace

SimulateSummary run_simulation(const SimulateOptions& options, const std::filesystem::path& out_dir,
                               const PhotonTransportProgress& progress) {
  const PhotonTransportOptions transport = simulation_transport(options);
  const CameraOptions camera = simulation_camera(options, transport);
  validate_photon_transport_options(transport);
  AtomicOutputDir out(out_dir);  // checks the folder can be made before the long simulation

  SimulateSummary summary;
  const bool monte_carlo = options.source == RadianceSource::kMonteCarlo;
  if (monte_carlo) {
    summary.transport = simulate_photon_transport(transport, progress);
  } else {
    if (options.profile_only) throw Error("--profile-only: needs the Monte Carlo source");
    summary.transport.options = transport;
  }
  const PhotonTransportResult& result = summary.transport;

  json truth = truth_record(options, transport, result, monte_carlo);
  if (!options.profile_only)
    write_camera_images(options, transport, camera, monte_carlo, out, summary, truth);
  check_finite_json(truth, "truth.json");
  write_file_atomically(out.temporary() / "truth.json", truth.dump(2) + "\n");
  summary.files.push_back("truth.json");
  out.commit();
  if (options.exitance_csv && monte_carlo)
    write_file_atomically(*options.exitance_csv, exitance_csv(result));
  return summary;
}

// The default field: wide enough for a fit to see 3.5 diffusion lengths (1 / sigma_tr), or 5
// transport mean free paths, of the slowest-falling channel beyond its exclusion radius, pixels a
// quarter of the shortest transport mean free path (0.02..0.1 mm, coarser when the field would pass
// 1024 pixels). The fit warns below 3 diffusion lengths; the old fixed 12.8 mm field gave marble
// 0.7 and a -8% sigma_a.
SimulationField default_simulation_field(const materials::Material& m, int size, double pixel_mm,
                                         bool size_given, bool pixel_given) {
  constexpr double kDiffusionLengths = 3.5, kMaxHalfWidthMm = 100;
  constexpr int kMaxSize = 1024;
  double half_width = 0, shortest_mfp = INFINITY;
  int slowest = -1;
  for (int c = 0; c < 3; ++c) {
    const double sa = m.sigma_a[c], ss = m.sigma_s_reduced[c];
    if (!(ss > 0)) continue;  // does not scatter: no profile to see
    const double st = sa + ss, sigma_tr = std::sqrt(3 * sa * st);
    shortest_mfp = std::min(shortest_mfp, 1 / st);
    // Beyond the fit's default exclusion (a tenth of a transport mean free path), and at least 5
    // transport mean free paths (near black, where 3.5 diffusion lengths are 2 of them).
    const double need = std::max(kDiffusionLengths / std::max(sigma_tr, 1e-300), 5 / st) + 0.1 / st;
    if (need > half_width) half_width = need, slowest = c;
  }
  SimulationField f{size, pixel_mm, ""};
  if (slowest < 0 || (size_given && pixel_given)) return f;
  half_width = std::min(half_width, kMaxHalfWidthMm);
  if (!pixel_given) f.pixel_mm = std::clamp(0.25 * shortest_mfp, 0.02, 0.1);
  if (!size_given) {
    double n = std::ceil(2 * half_width / f.pixel_mm);
    if (n > kMaxSize && !pixel_given) f.pixel_mm = 2 * half_width / kMaxSize, n = kMaxSize;
    f.size = int(std::clamp(n, 64.0, double(kMaxSize)));
  }
  const double sa = m.sigma_a[slowest], st = sa + m.sigma_s_reduced[slowest];
  std::ostringstream why;
  why.precision(3);
  why << "simulate: field " << f.size * f.pixel_mm << " mm (" << f.size << " pixels of "
      << f.pixel_mm << " mm), sized for "
      << "RGB"[slowest] << ", the slowest-falling channel ("
      << "1/sigma_tr = " << 1 / std::sqrt(3 * sa * st) << " mm; the half-width holds "
      << f.size * f.pixel_mm / 2 * std::sqrt(3 * sa * st) << " of them"
      << (half_width >= kMaxHalfWidthMm ? ", capped at 100 mm" : "")
      << "); --size and --pixel-mm choose";
  f.why = why.str();
  return f;
}

}  // namespace lucent::acquire
