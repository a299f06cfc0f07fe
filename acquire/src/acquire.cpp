#include "lucent/acquire/acquire.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "lucent/acquire/camera.h"
#include "lucent/acquire/capture.h"
#include "lucent/acquire/hdr_merge.h"
#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/imaging/camera_raw.h"
#include "lucent/imaging/image_io.h"
#include "lucent/version.h"

namespace lucent::acquire {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr double kPi = std::numbers::pi;
constexpr const char* kChannelNames[3] = {"R", "G", "B"};

std::string number(double value, int precision = 4) {
  std::ostringstream s;
  s.precision(precision);
  s << value;
  return s.str();
}

void validate(const AcquireOptions& o) {
  if (o.bins < 1) throw Error("--bins: expected at least 1 bin, found " + std::to_string(o.bins));
  if (o.min_pixels_per_bin < 2) {
    throw Error("--min-pixels: expected at least 2 (a standard error needs two pixels), found " +
                std::to_string(o.min_pixels_per_bin));
  }
  if (o.radius_mm && !(*o.radius_mm > 0 && std::isfinite(*o.radius_mm))) {
    throw Error("--radius-mm: expected a radius > 0 mm, found " + number(*o.radius_mm));
  }
  if (o.ring_every_bins < 1) throw Error("ring_every_bins: expected at least 1");
  if (!(o.beam.region_fraction > 0 && o.beam.region_fraction < 1)) {
    throw Error("beam.region_fraction: expected a fraction in (0, 1)");
  }
}

// Beam power from a Lambertian reference of reflectance rho: its radiance integrated over the plane
// is P rho / pi (docs/DESIGN.md §5), so P = (pi / rho) sum (L - background) pixel_area. The
// background (dark offsets left after subtraction, stray light) is the median of a ring of pixels
// along the border, far from the spot; black-masked pixels count as 0, non-finite ones as
// background.
struct BeamPower {
  std::array<double, 3> power{};
  std::array<double, 3> standard_error{};
  std::array<double, 3> background{};
  int border_px = 0;
};

BeamPower white_reference_power(const HdrResult& white, double reflectance, double pixel_pitch_mm,
                                const std::string& sources) {
  const int w = white.width(), h = white.height();
  BeamPower result;
  result.border_px = std::max(2, std::min(w, h) / 16);
  const double area = pixel_pitch_mm * pixel_pitch_mm;
  for (int c = 0; c < 3; ++c) {
    if (white.counts.saturated[c] > 0) {
      throw Error(sources + ": white reference has " + std::to_string(white.counts.saturated[c]) +
                  " pixels saturated in every image in channel " + kChannelNames[c] +
                  "; its beam power would be underestimated (use shorter exposures)");
    }
    std::vector<double> border;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const bool in_border = x < result.border_px || y < result.border_px ||
                               x >= w - result.border_px || y >= h - result.border_px;
        if (in_border && white.mask_at(x, y, c) != PixelMask::kNonFinite) {
          border.push_back(white.radiance.at(x, y, c));  // 0 where black-masked
        }
      }
    }
    if (!border.empty()) {
      std::nth_element(border.begin(), border.begin() + border.size() / 2, border.end());
      result.background[c] = border[border.size() / 2];
    }
    double sum = 0, variance = 0;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        if (white.mask_at(x, y, c) == PixelMask::kNonFinite) continue;
        sum += white.radiance.at(x, y, c) - result.background[c];
        variance += double(white.standard_error.at(x, y, c)) * white.standard_error.at(x, y, c);
      }
    }
    result.power[c] = kPi / reflectance * sum * area;
    result.standard_error[c] = kPi / reflectance * std::sqrt(variance) * area;
    if (!(result.power[c] > 0)) {
      throw Error(sources + ": white reference: the radiance above the background integrates to " +
                  number(result.power[c]) + " in channel " + kChannelNames[c] +
                  " (expected a positive beam power; is the spot in the image?)");
    }
  }
  return result;
}

// The system response the white reference records: its light, averaged over the channels
// (beam.h, system_response).
SystemResponse white_reference_response(const HdrResult& white, const BeamPower& power,
                                        double pixel_mm) {
  const int w = white.width(), h = white.height();
  std::vector<double> v(std::size_t(w) * h, 0.0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double sum = 0;
      for (int c = 0; c < 3; ++c)
        if (white.mask_at(x, y, c) != PixelMask::kNonFinite)
          sum += white.radiance.at(x, y, c) / power.power[c];
      v[std::size_t(y) * w + x] = sum / 3;
    }
  return system_response(v, w, h, pixel_mm);
}

// The picture for a person: log tone mapping between the 1st and 99.9th percentile luminance, sRGB,
// masked pixels magenta, the entry point as a cross and rings at every n-th bin edge. Small images
// are enlarged (nearest neighbour) so that the marks stay legible.
imaging::RawImage overview_image(const HdrResult& hdr, const std::array<double, 2>& beam_point_px,
                                 const std::vector<double>& edges_mm, double pixel_pitch_mm,
                                 int ring_every, const std::string& caption_top,
                                 const std::string& caption_bottom) {
  const int w = hdr.width(), h = hdr.height();
  const double kLum[3] = {0.2126, 0.7152, 0.0722};
  std::vector<double> luminance(std::size_t(w) * h, 0.0), positive;
  std::vector<std::uint8_t> masked(std::size_t(w) * h, 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * w + x;
      for (int c = 0; c < 3; ++c) {
        if (!hdr.valid(x, y, c))
          masked[i] = 1;
        else
          luminance[i] += kLum[c] * hdr.radiance.at(x, y, c);
      }
      if (!masked[i] && luminance[i] > 0) positive.push_back(luminance[i]);
    }
  }
  double lo = 1, hi = 10;
  if (!positive.empty()) {
    std::sort(positive.begin(), positive.end());
    lo = positive[std::size_t(0.01 * double(positive.size() - 1))];
    hi = positive[std::size_t(0.999 * double(positive.size() - 1))];
    if (!(hi > lo)) hi = lo * 10;
  }
  const double log_lo = std::log(lo), log_range = std::log(hi) - log_lo;

  const int scale = std::max(1, int(std::ceil(512.0 / std::max(w, h))));
  // Caption text grows with the image so that it stays readable when the picture is viewed whole.
  const double font = 0.38 * std::max(1.0, (w * scale) / 560.0);
  const int line_height = int(std::lround(42 * font));
  cv::Mat base(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * w + x;
      cv::Vec3b& out = base.at<cv::Vec3b>(y, x);  // RGB order throughout
      if (masked[i]) {
        out = cv::Vec3b(255, 0, 255);
        continue;
      }
      const double t = luminance[i] > 0
                           ? std::clamp((std::log(luminance[i]) - log_lo) / log_range, 0.0, 1.0)
                           : 0.0;
      for (int c = 0; c < 3; ++c) {
        const double chroma =
            luminance[i] > 0 ? std::max(0.0, double(hdr.radiance.at(x, y, c))) / luminance[i] : 0.0;
        out[c] = std::uint8_t(std::lround(255 * srgb_encode(std::min(1.0, t * chroma))));
      }
    }
  }
  cv::Mat image(h * scale + 2 * line_height + line_height / 3, w * scale, CV_8UC3,
                cv::Scalar(0, 0, 0));
  cv::Mat top = image(cv::Rect(0, 0, w * scale, h * scale));
  cv::resize(base, top, top.size(), 0, 0, cv::INTER_NEAREST);

  // OpenCV puts pixel centres at integer coordinates, we at +0.5 (beam.h): shift by half an output
  // pixel after scaling; draw with 4 fractional bits for sub-pixel placement.
  constexpr int kShift = 4;
  const auto fixed = [&](double length_px) {
    return int(std::lround(length_px * scale * (1 << kShift)));
  };
  const auto position = [&](double v_px) {
    return int(std::lround((v_px * scale - 0.5) * (1 << kShift)));
  };
  const cv::Point centre(position(beam_point_px[0]), position(beam_point_px[1]));
  const std::size_t bins = edges_mm.size() - 1;
  for (std::size_t b = std::size_t(ring_every); b <= bins; b += std::size_t(ring_every)) {
    const int radius = fixed(edges_mm[b] / pixel_pitch_mm);
    cv::circle(top, centre, radius, cv::Scalar(60, 220, 60), 1, cv::LINE_AA, kShift);
  }
  if (bins % std::size_t(ring_every) != 0) {  // the outer edge, always
    cv::circle(top, centre, fixed(edges_mm.back() / pixel_pitch_mm), cv::Scalar(60, 220, 60), 1,
               cv::LINE_AA, kShift);
  }
  // The cross: cyan on a dark outline, visible on the bright spot and on magenta alike.
  const int arm = std::max({6, 3 * scale, w * scale / 80}) << kShift;
  const int stroke = std::max(1, w * scale / 1000);
  for (const auto& [colour, thickness] : {std::pair{cv::Scalar(0, 0, 0), 2 * stroke + 1},
                                          std::pair{cv::Scalar(0, 255, 255), stroke}}) {
    cv::line(top, centre - cv::Point(arm, 0), centre + cv::Point(arm, 0), colour, thickness,
             cv::LINE_AA, kShift);
    cv::line(top, centre - cv::Point(0, arm), centre + cv::Point(0, arm), colour, thickness,
             cv::LINE_AA, kShift);
  }

  cv::putText(image, caption_top, cv::Point(4, h * scale + line_height), cv::FONT_HERSHEY_SIMPLEX,
              font, cv::Scalar(230, 230, 230), std::max(1, int(font * 2)), cv::LINE_AA);
  cv::putText(image, caption_bottom, cv::Point(4, h * scale + 2 * line_height),
              cv::FONT_HERSHEY_SIMPLEX, font, cv::Scalar(230, 230, 230), std::max(1, int(font * 2)),
              cv::LINE_AA);

  imaging::RawImage out(image.cols, image.rows, 255);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      for (int c = 0; c < 3; ++c) out.at(x, y, c) = image.at<cv::Vec3b>(y, x)[c];
    }
  }
  return out;
}

json noise_to_json(const NoiseModel& noise) {
  return {{"source", noise.source},
          {"gain", noise.gain},
          {"read_variance", noise.read_variance},
          {"samples", noise.samples}};
}

}  // namespace

namespace {

// run_acquire as named stages over one acquisition's state (the former locals of one long function,
// members under the same names): the sample's brackets merged, the beam located, the calibration
// (white reference or given power) and the system response, the profile binned and checked, its
// provenance, and the outputs written together.
class AcquireRun {
 public:
  AcquireRun(const fs::path& capture_json, const fs::path& out_dir, const AcquireOptions& options)
      : capture_json(capture_json), out_dir(out_dir), options(options),
        capture((validate(options), read_capture(capture_json))),
        out(out_dir),  // checks the folder can be made; removed again unless committed
        white_given(capture.white_reference.has_value()) {}

  AcquireSummary run() {
    merge_sample();
    locate_beam();
    calibrate();
    bin_profile();
    record_provenance();
    write_outputs();
    return summary;
  }

 private:
  // Stage weights: rough shares of the time on a large capture (the merges dominate).
  void progress(const char* stage, double done) const {
    if (options.progress) options.progress(stage, done);
  }
  void merge_sample();
  void locate_beam();
  void calibrate();
  void bin_profile();
  void record_provenance();
  void write_outputs();

  const fs::path& capture_json;
  const fs::path& out_dir;
  const AcquireOptions& options;
  const Capture capture;
  AtomicOutputDir out;
  const bool white_given;
  std::optional<ResponseCurve> curve;  // recovered once, shared with the white reference
  HdrResult hdr;
  int w = 0, h = 0;
  AcquireSummary summary;
  std::optional<BeamPoint> detected;
  std::array<double, 3> scale{kPi, kPi, kPi};  // pi L per unit power (or per second)
  json white_json = nullptr;
  SystemResponse response;
  std::vector<double> edges;  // the radial bins' edges, mm
  Profile profile;
};

void AcquireRun::merge_sample() {
  progress("merging the sample's brackets", 0.0);

  // Sample: one response for everything (a recovered curve is shared with the white reference).
  if (capture.response == Response::kCalibrate) {
    curve = calibrate_response(capture.sample, capture.base_dir);
  }
  hdr = merge_brackets(capture.sample, capture.response, capture.dark, capture.base_dir, curve);
  w = hdr.width(), h = hdr.height();

  summary.width = w;
  summary.height = h;
  summary.masked = hdr.counts;
}

void AcquireRun::locate_beam() {
  if (capture.beam_point_px) {
    const auto& p = *capture.beam_point_px;
    if (!(p[0] >= 0 && p[0] <= w && p[1] >= 0 && p[1] <= h)) {
      throw Error(capture_json.string() + ": field 'beam_point_px': (" + number(p[0]) + ", " +
                  number(p[1]) + ") lies outside the " + std::to_string(w) + "x" +
                  std::to_string(h) + " image (pixel centres at i + 0.5)");
    }
    summary.beam_point_px = p;
    summary.beam_point_source = "given";
  } else {
    detected = find_beam_point(hdr, hdr.sources_text, options.beam);
    summary.beam_point_px = detected->px;
    summary.beam_point_source = "detected";
  }
}

// The calibration: the white reference's beam power and system response, or a given power.
void AcquireRun::calibrate() {
  summary.beam_power_source = "none";
  if (capture.white_reference) {
    const WhiteReference& reference = *capture.white_reference;
    progress("merging the white reference", 0.45);
    const HdrResult white =
        merge_brackets(reference.images, capture.response, capture.dark, capture.base_dir, curve);
    if (white.iso_scaled != hdr.iso_scaled) {
      throw Error(capture_json.string() + ": field 'white_reference.images': the " +
                  (white.iso_scaled ? "white reference's" : "sample's") +
                  " brackets have an ISO and the " +
                  (white.iso_scaled ? "sample's" : "white reference's") +
                  " do not, so their radiances are on different scales (give 'iso' for both or "
                  "for neither)");
    }
    const BeamPower power = white_reference_power(white, reference.reflectance,
                                                  capture.pixel_pitch_mm, white.sources_text);
    summary.beam_power = power.power;
    summary.beam_power_source = "white reference";
    response = white_reference_response(white, power, capture.pixel_pitch_mm);
    white_json = {
        {"reflectance", reference.reflectance},
        {"beam_power_standard_error", power.standard_error},
        {"background", power.background},
        {"border_px", power.border_px},
        {"masked", {{"black", white.counts.black}, {"non_finite", white.counts.non_finite}}},
        {"noise_model", noise_to_json(white.noise)}};
  } else if (capture.beam_power) {
    summary.beam_power =
        std::array<double, 3>{*capture.beam_power, *capture.beam_power, *capture.beam_power};
    summary.beam_power_source = "capture";
  }
  summary.calibrated = summary.beam_power.has_value();
  if (summary.calibrated) {
    for (int c = 0; c < 3; ++c) scale[c] = kPi / (*summary.beam_power)[c];
  }
}

// Geometry and bins: the radius, the radial profile (and 2D samples at oblique incidence), checked.
void AcquireRun::bin_profile() {
  const auto& bp = summary.beam_point_px;
  const double edge_distance_px = std::min({bp[0], bp[1], w - bp[0], h - bp[1]});
  summary.radius_mm =
      options.radius_mm ? *options.radius_mm : edge_distance_px * capture.pixel_pitch_mm;
  if (!(summary.radius_mm > 0)) {
    throw Error(capture_json.string() + ": the beam entry point (" + number(bp[0]) + ", " +
                number(bp[1]) + ") px lies on the image edge; give --radius-mm");
  }
  if (options.log_bins && !(summary.radius_mm > capture.pixel_pitch_mm / 2)) {
    throw Error("--log-bins: the radius " + number(summary.radius_mm) +
                " mm is not above half a pixel pitch (" + number(capture.pixel_pitch_mm / 2) +
                " mm), where log-spaced bins start; give a larger --radius-mm");
  }
  RadialBinning binning;
  binning.bins = options.bins;
  binning.log_bins = options.log_bins;
  binning.radius_mm = summary.radius_mm;
  binning.min_pixels_per_bin = options.min_pixels_per_bin;
  edges = radial_bin_edges_mm(binning, capture.pixel_pitch_mm);

  progress("binning the profile", white_given ? 0.8 : 0.6);
  profile.calibrated = summary.calibrated;
  profile.capture = capture_json.string();
  profile.pixel_pitch_mm = capture.pixel_pitch_mm;
  profile.incidence_polar_deg = capture.incidence_polar_deg;
  profile.incidence_azimuth_deg = capture.incidence_azimuth_deg;
  profile.view_deg = capture.view_deg;
  profile.ior = capture.ior;
  profile.thickness_mm = capture.thickness_mm;
  profile.transmitted = capture.transmitted;
  profile.response_r_mm = response.r_mm;
  profile.response_value = response.value;
  profile.response_rms_mm = response.rms_mm;
  profile.beam_point_px = bp;
  profile.beam_point_source = summary.beam_point_source;
  profile.beam_power = summary.beam_power;
  profile.masked = hdr.counts;
  profile.radial = bin_radial_profile(hdr, bp, capture.pixel_pitch_mm, scale, binning);
  if (profile.radial.size() == 0) {
    throw Error(capture_json.string() + ": no radial bin has " +
                std::to_string(options.min_pixels_per_bin) +
                " unmasked pixels in every channel within " + number(summary.radius_mm) +
                " mm of the entry point (use fewer --bins or a larger --radius-mm)");
  }
  // A calibrated sample cannot return more light than came in: integrated over the field, pi L per
  // unit power is about the diffuse reflectance (exactly so for a Lambertian exit), at most 1. A
  // sample 1.5 times brighter than that says the white reference is wrong (50 times darker than
  // the sample gave sigma_a = 3.6e-112 with exit 0).
  if (summary.calibrated) {
    for (int c = 0; c < 3; ++c) {
      double total = 0;
      for (std::size_t i = 0; i < profile.radial.size(); ++i)
        total += profile.radial.value[c][i] * std::numbers::pi *
                 (profile.radial.r_outer_mm[i] * profile.radial.r_outer_mm[i] -
                  profile.radial.r_inner_mm[i] * profile.radial.r_inner_mm[i]);
      if (total > 1.5)
        throw Error(capture_json.string() + ": field 'white_reference': the sample returns " +
                    number(total, 3) + " times the light the white reference says reached it (" +
                    "RGB"[c] + " channel): a white reference darker than the sample (another " +
                    "beam power, exposure or gain?)");
    }
  }
  if (capture.incidence_polar_deg > 0) {
    profile.samples_2d =
        sample_2d_profile(hdr, bp, capture.pixel_pitch_mm, scale, summary.radius_mm);
    summary.samples_2d = int(profile.samples_2d->size());
  }
  summary.bins_written = int(profile.radial.size());
}

void AcquireRun::record_provenance() {
  json provenance = {
      {"tool", "lucent acquire"},
      {"version", kVersion},
      {"response", to_string(capture.response)},
      {"input", capture.sample.hdr ? "hdr" : "brackets"},
      {"image_size_px", {w, h}},
      {"pixel_centre_convention", "pixel (i, j) has its centre at (i + 0.5, j + 0.5)"},
      {"dark", capture.dark ? json(capture.dark->generic_string()) : json(nullptr)},
      {"radius_mm", summary.radius_mm},
      {"bins", options.bins},
      {"log_bins", options.log_bins},
      {"min_pixels_per_bin", options.min_pixels_per_bin},
      {"bins_dropped", options.bins - summary.bins_written},
      {"radial_standard_error",
       "max(sample standard deviation / sqrt(n), sqrt(sum of pixel variances) / n)"},
      {"noise_model", noise_to_json(hdr.noise)},
      {"beam_power_source", summary.beam_power_source},
      {"white_reference", white_json}};
  if (!capture.sample.hdr) {
    provenance["exposures_s"] = hdr.exposure_s;
    if (hdr.iso_scaled) provenance["exposures_scaled_by"] = "ISO / 100";
    if (hdr.camera_raw) {
      provenance["camera_raw"] = "2x2 Bayer quads, black and white levels from the files (" +
                                 imaging::camera_raw_decoder_version() + ")";
    }
  }
  if (detected) {
    provenance["beam_detection"] = {{"peak_luminance", detected->peak},
                                    {"background_luminance", detected->background},
                                    {"noise_luminance", detected->noise},
                                    {"region_pixels", detected->region_pixels},
                                    {"saturated_pixels", detected->saturated_pixels}};
  }
  if (!capture.provenance.is_null()) provenance["capture_provenance"] = capture.provenance;
  profile.provenance = provenance;
}

void AcquireRun::write_outputs() {
  const auto& bp = summary.beam_point_px;
  // capture.exr: radiance per unit beam power when calibrated (comparable with the simulator's
  // truth), per second of exposure in the capture's units otherwise.
  imaging::ImageRgb radiance = hdr.radiance;
  if (summary.calibrated) {
    for (std::size_t i = 0; i < radiance.data.size(); ++i) {
      radiance.data[i] = float(radiance.data[i] / (*summary.beam_power)[i % 3]);
    }
  }
  std::int64_t masked_pixels = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      masked_pixels += !(hdr.valid(x, y, 0) && hdr.valid(x, y, 1) && hdr.valid(x, y, 2));
    }
  }
  const std::string caption_top = "entry (" + number(bp[0], 6) + ", " + number(bp[1], 6) + ") px " +
                                  summary.beam_point_source +
                                  "; masked: " + std::to_string(masked_pixels) + " px (magenta)";
  const std::string caption_bottom = "rings every " + std::to_string(options.ring_every_bins) +
                                     " bins (" + (options.log_bins ? "log" : "linear") +
                                     "), outer " + number(summary.radius_mm) + " mm" +
                                     (summary.calibrated ? "" : "; uncalibrated");
  const imaging::RawImage overview = overview_image(
      hdr, bp, edges, capture.pixel_pitch_mm, options.ring_every_bins, caption_top, caption_bottom);

  const std::map<std::string, std::string> attributes = {
      {"lucent.format", "lucent-hdr-capture"},
      {"lucent.version", "1"},
      {"units", summary.calibrated
                    ? "radiance per unit beam power, mm^-2 sr^-1 (L / P)"
                    : "radiance per second of exposure, capture units (uncalibrated)"},
      {"lucent.masked",
       "0 where masked (saturated or black in every bracket, or non-finite); "
       "counts in profile.json"},
      {"lucent.capture", capture_json.string()}};
  progress("writing", 0.92);
  imaging::write_exr(out.temporary() / "capture.exr", radiance, attributes);
  write_profile(out.temporary() / "profile.json", profile);
  write_file_atomically(out.temporary() / "profile.csv", profile_csv(profile));
  imaging::write_png(out.temporary() / "acquire.png", overview);
  out.commit();
  for (const char* name : {"capture.exr", "profile.json", "profile.csv", "acquire.png"}) {
    summary.files.push_back(out_dir / name);
  }
}

}  // namespace

AcquireSummary run_acquire(const fs::path& capture_json, const fs::path& out_dir,
                           const AcquireOptions& options) {
  return AcquireRun(capture_json, out_dir, options).run();
}

json summary_to_json(const AcquireSummary& s) {
  return {{"beam_point_px", s.beam_point_px},
          {"beam_point_source", s.beam_point_source},
          {"calibrated", s.calibrated},
          {"beam_power", s.beam_power ? json(*s.beam_power) : json(nullptr)},
          {"beam_power_source", s.beam_power_source},
          {"masked",
           {{"saturated", s.masked.saturated},
            {"black", s.masked.black},
            {"non_finite", s.masked.non_finite}}},
          {"image_size_px", {s.width, s.height}},
          {"radius_mm", s.radius_mm},
          {"bins_written", s.bins_written},
          {"samples_2d", s.samples_2d},
          {"files", [&] {
             json files = json::array();
             for (const auto& f : s.files) files.push_back(f.string());
             return files;
           }()}};
}

std::string to_string(const AcquireSummary& s) {
  std::ostringstream out;
  out << "entry point: (" << number(s.beam_point_px[0], 6) << ", " << number(s.beam_point_px[1], 6)
      << ") px, " << s.beam_point_source << "\n";
  if (s.beam_power) {
    out << "beam power (" << s.beam_power_source << "): R " << number((*s.beam_power)[0]) << ", G "
        << number((*s.beam_power)[1]) << ", B " << number((*s.beam_power)[2])
        << " (radiance units x mm^2 sr); profile per mm^2\n";
  } else {
    out << "beam power: unknown (no white reference or beam_power); profile is relative\n";
  }
  const auto triple = [](const std::array<std::int64_t, 3>& v) {
    return std::to_string(v[0]) + "/" + std::to_string(v[1]) + "/" + std::to_string(v[2]);
  };
  out << "masked pixels (R/G/B): saturated " << triple(s.masked.saturated) << ", black "
      << triple(s.masked.black) << ", non-finite " << triple(s.masked.non_finite) << "\n";
  out << "radial bins: " << s.bins_written << " within " << number(s.radius_mm) << " mm";
  if (s.samples_2d > 0) out << "; 2D samples: " << s.samples_2d;
  out << "\nwrote:";
  for (const auto& f : s.files) out << " " << f.string();
  out << "\n";
  return out.str();
}

}  // namespace lucent::acquire
