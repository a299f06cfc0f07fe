#include "lucent/acquire/hdr_merge.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/photo.hpp>

#include "hdr_merge_impl.h"
#include "lucent/acquire/camera.h"
#include "lucent/core/error.h"
#include "lucent/imaging/image_io.h"

namespace lucent::acquire {
namespace {

using detail::fit_neighbour_noise;
using detail::fit_variance_model;
using detail::NoiseRow;
using detail::quantisation_variance;
using detail::Stack;

namespace fs = std::filesystem;

constexpr const char* kChannelNames[3] = {"R", "G", "B"};

// Widths of the weight's ramps, as fractions of the code range: see the file comment of
// hdr_merge.h.
constexpr double kLowRamp = 0.01;
constexpr double kHighRamp = 0.02;

// Debevec calibration: pixels sampled on a grid and the smoothness weight lambda (OpenCV's default,
// 10). OpenCV's default of 70 samples left errors up to 9% on simulated 8-bit sRGB captures; 200
// brought them within 3% for about 0.5 s more (the solve does not grow with the image).
constexpr int kDebevecSamples = 200;
constexpr float kDebevecSmoothing = 10.0f;

fs::path resolve(const fs::path& base_dir, const fs::path& path) {
  return path.is_absolute() || base_dir.empty() ? path : base_dir / path;
}

std::string size_text(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

// "a.png", "a.png, b.png" or "a.png, ..., e.png (5 images)": errors name the files in one line.
std::string describe_sources(const std::vector<fs::path>& paths) {
  if (paths.empty()) return "(no images)";
  if (paths.size() == 1) return paths.front().string();
  if (paths.size() == 2) return paths[0].string() + ", " + paths[1].string();
  return paths.front().string() + ", ..., " + paths.back().string() + " (" +
         std::to_string(paths.size()) + " images)";
}

// Weight ramp h(v): exactly 0 at code 0 and at codes >= max - 1.
double taper(int v, int max_value) {
  const double top = max_value - 1;
  if (v <= 0 || v >= top) return 0.0;
  return std::min({1.0, v / (kLowRamp * top), (top - v) / (kHighRamp * top)});
}

bool is_camera_raw(const imaging::RawImage& image) {
  return image.black != std::array<double, 3>{0.0, 0.0, 0.0} ||
         (image.max_value != 255 && image.max_value != 65535) || image.metadata.exposure_s ||
         image.metadata.iso;
}

std::string code_range(const imaging::RawImage& image) {
  if (image.max_value == 255 && !is_camera_raw(image)) return "8-bit";
  if (image.max_value == 65535 && !is_camera_raw(image)) return "16-bit";
  char text[96];
  std::snprintf(text, sizeof text, "RAW with black %.6g/%.6g/%.6g and white %d", image.black[0],
                image.black[1], image.black[2], image.max_value);
  return text;
}

// Reads the brackets, takes exposure times and ISO from RAW metadata where the capture leaves them
// out, and orders them by effective exposure (the time scaled by ISO / 100 when every image's ISO
// is known: a RAW code grows with the sensor gain the ISO sets).
Stack read_stack(const ImageSet& set, const fs::path& base_dir) {
  struct Read {
    imaging::RawImage image;
    double exposure_s;
    std::optional<double> iso;
    fs::path path;
  };
  std::vector<Read> read;
  for (const Bracket& b : set.images) {
    const fs::path path = resolve(base_dir, b.path);
    imaging::RawImage image = imaging::read_raw_image(path);
    const double t = b.exposure_s > 0 ? b.exposure_s : image.metadata.exposure_s.value_or(0.0);
    if (!(t > 0)) {
      throw Error(path.string() +
                  ": no exposure time in the file's metadata; give 'exposure_s' in the capture");
    }
    const std::optional<double> iso = b.iso ? b.iso : image.metadata.iso;
    if (!read.empty()) {
      const imaging::RawImage& first = read.front().image;
      const fs::path& first_path = read.front().path;
      if (image.width != first.width || image.height != first.height) {
        throw Error(path.string() + ": image is " + size_text(image.width, image.height) +
                    " pixels but " + first_path.string() + " is " +
                    size_text(first.width, first.height) + " (all brackets must have one size)");
      }
      if (image.max_value != first.max_value || image.black != first.black) {
        throw Error(path.string() + ": " + code_range(image) + " but " + first_path.string() +
                    " is " + code_range(first) +
                    " (all brackets must have one bit depth and one black and white level)");
      }
      if (iso.has_value() != read.front().iso.has_value()) {
        const fs::path& without = iso ? first_path : path;
        throw Error(without.string() +
                    ": no ISO, while another bracket of the set has one (give "
                    "'iso' for every image of the set, or for none)");
      }
    }
    read.push_back({std::move(image), t, iso, path});
  }
  if (read.empty()) throw Error("no images to merge");
  for (Read& r : read) {
    if (r.iso) r.exposure_s *= *r.iso / 100.0;
  }
  std::stable_sort(read.begin(), read.end(),
                   [](const Read& a, const Read& b) { return a.exposure_s < b.exposure_s; });
  Stack stack;
  stack.iso_known = read.front().iso.has_value();
  for (std::size_t k = 0; k < read.size(); ++k) {
    if (k > 0 && !(read[k].exposure_s > read[k - 1].exposure_s)) {
      throw Error(read[k].path.string() + ": same exposure as " + read[k - 1].path.string() +
                  " (exposures must differ from one bracket to the next)");
    }
    stack.images.push_back(std::move(read[k].image));
    stack.exposure_s.push_back(read[k].exposure_s);
    stack.paths.push_back(read[k].path);
  }
  if (stack.images.empty()) throw Error("no images to merge");
  return stack;
}

// After masking: a channel without any usable pixel is an error, named by its cause.
void require_usable_pixels(const HdrResult& result, const std::string& sources) {
  const std::int64_t pixels = std::int64_t(result.radiance.width) * result.radiance.height;
  const MaskCounts& m = result.counts;
  bool all_saturated = true, all_black = true, all_non_finite = true, any_empty = false;
  int empty_channel = -1;
  for (int c = 0; c < 3; ++c) {
    all_saturated = all_saturated && m.saturated[c] == pixels;
    all_black = all_black && m.black[c] == pixels;
    all_non_finite = all_non_finite && m.non_finite[c] == pixels;
    if (m.total(c) == pixels && !any_empty) any_empty = true, empty_channel = c;
  }
  if (!any_empty) return;
  if (all_non_finite) throw Error(sources + ": no finite pixels (every pixel is NaN or Inf)");
  if (all_saturated) {
    throw Error(sources +
                ": all-saturated stack: every pixel is saturated in every image "
                "(use shorter exposures)");
  }
  if (all_black) {
    throw Error(sources +
                ": all-black stack: every pixel is black (code 0 or at the dark level) in "
                "every image (use longer exposures)");
  }
  const int c = empty_channel;
  const std::string name = kChannelNames[c];
  if (m.non_finite[c] == pixels) {
    throw Error(sources + ": no finite pixels in channel " + name + " (every pixel is NaN or Inf)");
  }
  if (m.saturated[c] == pixels) {
    throw Error(sources + ": all-saturated stack in channel " + name +
                ": every pixel is saturated in every image (use shorter exposures)");
  }
  if (m.black[c] == pixels) {
    throw Error(sources + ": all-black stack in channel " + name +
                ": every pixel is black in every image (use longer exposures)");
  }
  throw Error(sources + ": no usable pixel in channel " + name + " (" +
              std::to_string(m.saturated[c]) + " saturated, " + std::to_string(m.black[c]) +
              " black, " + std::to_string(m.non_finite[c]) + " non-finite)");
}

HdrResult read_hdr(const ImageSet& set, const std::optional<fs::path>& dark,
                   const fs::path& base_dir) {
  HdrResult result;
  const fs::path path = resolve(base_dir, *set.hdr);
  result.sources = {path};
  result.sources_text = path.string();
  result.radiance = imaging::read_exr(path);
  const int w = result.radiance.width, h = result.radiance.height;
  imaging::ImageRgb dark_image;
  if (dark) {
    const fs::path dark_path = resolve(base_dir, *dark);
    std::string ext = dark_path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char ch) { return std::tolower(ch); });
    if (ext != ".exr") {
      throw Error(dark_path.string() +
                  ": with an 'hdr' capture the dark frame must be an OpenEXR "
                  "image in the same units");
    }
    dark_image = imaging::read_exr(dark_path);
    if (dark_image.width != w || dark_image.height != h) {
      throw Error(dark_path.string() + ": dark frame is " +
                  size_text(dark_image.width, dark_image.height) + " pixels but " + path.string() +
                  " is " + size_text(w, h));
    }
    result.sources.push_back(dark_path);
  }
  result.standard_error = imaging::ImageRgb(w, h, 0.0f);
  result.mask.assign(result.radiance.data.size(), PixelMask::kValid);
  for (std::size_t i = 0; i < result.radiance.data.size(); ++i) {
    float& value = result.radiance.data[i];
    if (dark) value -= dark_image.data[i];
    if (!std::isfinite(value)) {
      value = 0.0f;
      result.mask[i] = PixelMask::kNonFinite;
      ++result.counts.non_finite[i % 3];
    }
  }
  require_usable_pixels(result, path.string());
  fit_neighbour_noise(result);
  for (std::size_t i = 0; i < result.radiance.data.size(); ++i) {
    if (result.mask[i] != PixelMask::kValid) continue;
    const int c = int(i % 3);
    const double variance = result.noise.gain[c] * std::max(0.0, double(result.radiance.data[i])) +
                            result.noise.read_variance[c];
    result.standard_error.data[i] = float(std::sqrt(std::max(variance, 0.0)));
  }
  return result;
}

// What every stage of merge_stack reads: the stack, its curve, the dark frame, and the tables
// derived from them once (the weight ramp h(v), each code's quantisation variance).
struct MergeInputs {
  const Stack& stack;
  const ResponseCurve& curve;
  const std::optional<imaging::RawImage>& dark;
  int w, h, m, top;
  std::size_t n, brackets;
  std::vector<double> ramp;
  std::array<std::vector<double>, 3> q2;

  MergeInputs(const Stack& s, const ResponseCurve& c, const std::optional<imaging::RawImage>& d)
      : stack(s), curve(c), dark(d) {
    const imaging::RawImage& first = s.images.front();
    w = first.width, h = first.height, m = first.max_value, top = m - 1;
    n = first.data.size(), brackets = s.images.size();
    ramp.resize(std::size_t(m) + 1);
    for (int v = 0; v <= m; ++v) ramp[std::size_t(v)] = taper(v, m);
    q2 = quantisation_variance(c);
  }

  // The stages, in order (each reads the tables above).
  std::vector<double> mask_and_first_pass(HdrResult& result) const;
  bool fit_bracket_noise(const std::vector<double>& first_pass, HdrResult& result) const;
  std::vector<double> smoothed_first_pass(const HdrResult& result,
                                          const std::vector<double>& first_pass) const;
  void final_merge(const std::vector<double>& smooth_pass, bool from_pairs,
                   HdrResult& result) const;
};

// Stage 1: each pixel's mask and counts, and a first merge with the shot-noise weights h t_k.
std::vector<double> MergeInputs::mask_and_first_pass(HdrResult& result) const {
  std::vector<double> first_pass(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const int c = int(i % 3);
    const int dark_code = dark ? dark->data[i] : -1;
    bool all_saturated = true, all_black = true;
    double sum_w = 0, sum_wx = 0;
    const double d = dark ? curve.linear[c][dark_code] : 0.0;
    for (std::size_t k = 0; k < brackets; ++k) {
      const int v = stack.images[k].data[i];
      all_saturated = all_saturated && v >= top;
      // Black means censored: code 0, below what the sensor can represent. A code at the dark
      // frame's level is a measurement of (nearly) no light, not a censored one: masking those
      // would keep only the pixels that noise lifted above the dark level and bias the faint
      // tail upward (a floor in the profile).
      all_black = all_black && v == 0;
      const double weight = ramp[v] * stack.exposure_s[k];
      if (weight > 0) {
        sum_w += weight;
        sum_wx += weight * (curve.linear[c][v] - d) / stack.exposure_s[k];
      }
    }
    PixelMask mask = PixelMask::kValid;
    if (all_saturated) {
      mask = PixelMask::kSaturated;
    } else if (all_black) {
      mask = PixelMask::kBlack;
    } else if (sum_w == 0) {
      // No usable code although neither all saturated nor all black (a gap in the bracketing).
      mask = stack.images.back().data[i] >= top ? PixelMask::kSaturated : PixelMask::kBlack;
    }
    result.mask[i] = mask;
    if (mask == PixelMask::kSaturated) ++result.counts.saturated[c];
    if (mask == PixelMask::kBlack) ++result.counts.black[c];
    if (mask == PixelMask::kValid) first_pass[i] = sum_wx / sum_w;
  }
  require_usable_pixels(result, result.sources_text);
  return first_pass;
}

// Stage 2: the noise model from consecutive usable brackets. Returns whether there were enough
// pairs (kMinNoisePairs) to fit it.
bool MergeInputs::fit_bracket_noise(const std::vector<double>& first_pass,
                                    HdrResult& result) const {
  // Noise model from consecutive usable brackets: d = x_k - x_k', E[d^2] = g A + s B + Q. Two
  // parameters need no more than ~1e5 pixels: larger images are subsampled on a regular stride.
  constexpr std::size_t kNoisePixels = 100000;
  const std::size_t stride = std::max<std::size_t>(1, (n / 3) / kNoisePixels);
  std::array<std::vector<NoiseRow>, 3> rows;
  std::array<std::vector<double>, 3> floors;
  for (std::size_t i = 0; i < n; ++i) {
    if (result.mask[i] != PixelMask::kValid || (i / 3) % stride != 0) continue;
    const int c = int(i % 3);
    const double d = dark ? curve.linear[c][dark->data[i]] : 0.0;
    const double dark_q2 = dark ? q2[c][dark->data[i]] : 0.0;
    const double signal = std::max(first_pass[i], 0.0);
    int previous = -1;
    for (std::size_t k = 0; k < brackets; ++k) {
      const int v = stack.images[k].data[i];
      if (ramp[v] <= 0) continue;
      if (previous >= 0) {
        const int u = stack.images[previous].data[i];
        const double t0 = stack.exposure_s[previous], t1 = stack.exposure_s[k];
        const double difference = (curve.linear[c][u] - d) / t0 - (curve.linear[c][v] - d) / t1;
        const double dark_factor = dark ? (1 / t0 - 1 / t1) * (1 / t0 - 1 / t1) : 0.0;
        const double a = signal * (1 / t0 + 1 / t1);
        const double b = 1 / (t0 * t0) + 1 / (t1 * t1) + dark_factor;
        const double q = q2[c][u] / (t0 * t0) + q2[c][v] / (t1 * t1) + dark_q2 * dark_factor;
        rows[c].push_back({a, b, difference * difference - q, 1.0});
        floors[c].push_back(q);
      }
      previous = int(k);
    }
  }
  const std::int64_t pairs =
      std::int64_t(std::min({rows[0].size(), rows[1].size(), rows[2].size()}));
  const bool from_pairs = pairs >= kMinNoisePairs;
  if (from_pairs) {
    result.noise.source = "bracket pairs";
    for (int c = 0; c < 3; ++c) {
      const auto [g, s] = fit_variance_model(rows[c], floors[c]);
      result.noise.gain[c] = g;
      result.noise.read_variance[c] = s;
      result.noise.samples += std::int64_t(rows[c].size());
    }
  }
  return from_pairs;
}

// Stage 3: the first pass averaged over 5 x 5 pixels (valid ones only): the signal the final
// weights come from.
std::vector<double> MergeInputs::smoothed_first_pass(const HdrResult& result,
                                                     const std::vector<double>& first_pass) const {
  std::vector<double> smooth_pass(n, 0.0);
  {
    std::vector<double> valid(n, 0.0), value(n, 0.0);
    for (std::size_t i = 0; i < n; ++i)
      if (result.mask[i] == PixelMask::kValid) valid[i] = 1, value[i] = first_pass[i];
    cv::Mat v(h, w, CV_64FC3, value.data()), m(h, w, CV_64FC3, valid.data());
    cv::Mat vs, ms;
    cv::boxFilter(v, vs, -1, cv::Size(5, 5), cv::Point(-1, -1), false, cv::BORDER_REPLICATE);
    cv::boxFilter(m, ms, -1, cv::Size(5, 5), cv::Point(-1, -1), false, cv::BORDER_REPLICATE);
    const double* a = vs.ptr<double>();
    const double* b = ms.ptr<double>();
    for (std::size_t i = 0; i < n; ++i) smooth_pass[i] = b[i] > 0 ? a[i] / b[i] : first_pass[i];
  }
  return smooth_pass;
}

// Stage 4: the final merge with inverse-variance weights (or the first pass, when the model is
// unknown), and the propagated standard error. The dark frame is shared by all brackets: its noise
// enters the merged value once, through sum_k w_k / t_k. Quantisation never vanishes for a real
// curve; the floor (1e-7 of full scale, squared) guards a flat stretch of a recovered (Debevec)
// curve with no fitted noise against infinite weights.
void MergeInputs::final_merge(const std::vector<double>& smooth_pass, bool from_pairs,
                              HdrResult& result) const {
  std::array<double, 3> variance_floor{};
  for (int c = 0; c < 3; ++c)
    variance_floor[c] = std::pow(1e-7 * std::abs(curve.linear[c][m]), 2) + 1e-300;
  std::vector<float> quantisation_only(from_pairs ? 0 : n, 0.0f);
  for (std::size_t i = 0; i < n; ++i) {
    if (result.mask[i] != PixelMask::kValid) continue;
    const int c = int(i % 3);
    const double g = result.noise.gain[c], s = result.noise.read_variance[c];
    const double d = dark ? curve.linear[c][dark->data[i]] : 0.0;
    const double dark_variance = dark ? s + q2[c][dark->data[i]] : 0.0;
    // The weights use the neighbourhood's signal, not this pixel's: a weight computed from the
    // pixel's own noisy value correlates with its noise and biases faint pixels upward.
    const double signal = std::max(smooth_pass[i], 0.0);
    double sum_w = 0, sum_wx = 0, sum_w2v = 0, sum_w2q = 0, sum_w_over_t = 0;
    for (std::size_t k = 0; k < brackets; ++k) {
      const int v = stack.images[k].data[i];
      if (v >= top) continue;  // saturated: clipped, no measurement
      // The weight comes from the code the first-pass signal predicts, not from the observed
      // code: weights that grow with the observed (noisy) code favour upward fluctuations and
      // bias faint pixels upward.
      const double t = stack.exposure_s[k];
      const std::vector<double>& f = curve.linear[c];
      const int predicted = int(std::lower_bound(f.begin(), f.end(), signal * t + d) - f.begin());
      if (predicted >= top) continue;  // this bracket is expected to saturate
      const double hat = ramp[std::size_t(std::max(predicted, 1))];
      const double variance = std::max(g * signal * t + s + q2[c][v], variance_floor[c]) / (t * t);
      const double weight = from_pairs ? hat / variance : hat * t;
      sum_w += weight;
      sum_wx += weight * (curve.linear[c][v] - d) / t;
      sum_w2v += weight * weight * variance;
      sum_w2q += weight * weight * q2[c][v] / (t * t);
      sum_w_over_t += weight / t;
    }
    const double value = sum_wx / sum_w;
    const double dark_term = dark_variance * (sum_w_over_t / sum_w) * (sum_w_over_t / sum_w);
    result.radiance.data[i] = float(value);
    result.standard_error.data[i] = float(std::sqrt(sum_w2v / (sum_w * sum_w) + dark_term));
    if (!from_pairs) quantisation_only[i] = float(sum_w2q / (sum_w * sum_w));
  }
  if (!from_pairs) {
    // One bracket (or too few overlapping ones): noise from the image itself, never below the
    // quantisation the codes imply.
    fit_neighbour_noise(result);
    for (std::size_t i = 0; i < n; ++i) {
      if (result.mask[i] != PixelMask::kValid) continue;
      const int c = int(i % 3);
      const double variance =
          result.noise.gain[c] * std::max(0.0, double(result.radiance.data[i])) +
          result.noise.read_variance[c];
      result.standard_error.data[i] =
          float(std::sqrt(std::max(variance, double(quantisation_only[i]))));
    }
  }
}

HdrResult merge_stack(const Stack& stack, const ResponseCurve& curve,
                      const std::optional<imaging::RawImage>& dark) {
  const MergeInputs in(stack, curve, dark);
  HdrResult result;
  result.radiance = imaging::ImageRgb(in.w, in.h, 0.0f);
  result.standard_error = imaging::ImageRgb(in.w, in.h, 0.0f);
  result.mask.assign(in.n, PixelMask::kValid);
  result.sources = stack.paths;
  result.sources_text = describe_sources(stack.paths);
  result.response = curve;
  const std::vector<double> first_pass = in.mask_and_first_pass(result);
  const bool from_pairs = in.fit_bracket_noise(first_pass, result);
  in.final_merge(in.smoothed_first_pass(result, first_pass), from_pairs, result);
  return result;
}

}  // namespace

ResponseCurve standard_response(Response kind, int max_value, const std::array<double, 3>& black) {
  if (kind == Response::kCalibrate) {
    throw Error("response 'calibrate': the curve is recovered from the brackets, not standard");
  }
  if (!(max_value >= 2 && max_value <= 65535)) {
    throw Error("response: max value " + std::to_string(max_value) + " (expected 2..65535)");
  }
  ResponseCurve curve;
  curve.kind = kind;
  curve.max_value = max_value;
  for (int c = 0; c < 3; ++c) {
    if (!(black[c] >= 0 && black[c] < max_value - 1)) {
      throw Error("response: black level " + std::to_string(black[c]) +
                  " is not below the white level " + std::to_string(max_value));
    }
    std::vector<double>& table = curve.linear[c];
    table.resize(std::size_t(max_value) + 1);
    for (int v = 0; v <= max_value; ++v) {
      const double encoded = (v - black[c]) / (max_value - black[c]);
      table[v] = kind == Response::kSrgb ? srgb_decode(encoded) : encoded;
    }
  }
  return curve;
}

ResponseCurve calibrate_response(const ImageSet& brackets, const fs::path& base_dir) {
  if (brackets.hdr) {
    throw Error(resolve(base_dir, *brackets.hdr).string() +
                ": response 'calibrate' needs exposure brackets, not an HDR image");
  }
  const Stack stack = read_stack(brackets, base_dir);
  if (stack.images.front().max_value != 255 || is_camera_raw(stack.images.front())) {
    throw Error(stack.paths.front().string() +
                ": response 'calibrate' needs 8-bit brackets (OpenCV's CalibrateDebevec), found " +
                code_range(stack.images.front()) + "; use response 'linear' (or 'srgb')");
  }
  if (stack.images.size() < 2) {
    throw Error(stack.paths.front().string() +
                ": response 'calibrate' needs at least two exposures to recover the curve");
  }
  std::vector<cv::Mat> mats;
  std::vector<float> times;
  for (std::size_t k = 0; k < stack.images.size(); ++k) {
    const imaging::RawImage& image = stack.images[k];
    cv::Mat mat(image.height, image.width, CV_8UC3);
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        for (int c = 0; c < 3; ++c) mat.at<cv::Vec3b>(y, x)[c] = std::uint8_t(image.at(x, y, c));
      }
    }
    mats.push_back(mat);
    times.push_back(float(stack.exposure_s[k]));
  }
  cv::Mat response;
  try {
    cv::createCalibrateDebevec(kDebevecSamples, kDebevecSmoothing)->process(mats, response, times);
  } catch (const cv::Exception& e) {
    throw Error(describe_sources(stack.paths) + ": response calibration failed: " + e.what());
  }
  ResponseCurve curve;
  curve.kind = Response::kCalibrate;
  curve.max_value = 255;
  for (int c = 0; c < 3; ++c) {
    curve.linear[c].resize(256);
    for (int v = 0; v < 256; ++v) {
      const double value = response.at<cv::Vec3f>(v)[c];
      if (!std::isfinite(value)) {
        throw Error(describe_sources(stack.paths) +
                    ": response calibration gave a non-finite curve (too little overlap between "
                    "the exposures?)");
      }
      curve.linear[c][v] = value;
    }
  }
  return curve;
}

HdrResult merge_brackets(const ImageSet& set, Response response,
                         const std::optional<fs::path>& dark, const fs::path& base_dir,
                         const std::optional<ResponseCurve>& curve) {
  if (set.hdr) return read_hdr(set, dark, base_dir);
  const Stack stack = read_stack(set, base_dir);
  const imaging::RawImage& first = stack.images.front();
  const int max_value = first.max_value;
  if (is_camera_raw(first) &&
      (response != Response::kLinear || (curve && curve->kind != Response::kLinear))) {
    throw Error(stack.paths.front().string() +
                ": field 'response': camera RAW codes are linear; "
                "use \"linear\" (found \"" +
                to_string(curve ? curve->kind : response) + "\")");
  }
  ResponseCurve used;
  if (curve) {
    used = *curve;
    if (used.max_value != max_value) {
      throw Error(stack.paths.front().string() + ": " + code_range(first) +
                  ", but the response curve is for codes 0.." + std::to_string(used.max_value));
    }
    if (is_camera_raw(first)) used = standard_response(Response::kLinear, max_value, first.black);
  } else if (response == Response::kCalibrate) {
    used = calibrate_response(set, base_dir);
  } else {
    used = standard_response(response, max_value, first.black);
  }
  std::optional<imaging::RawImage> dark_image;
  if (dark) {
    const fs::path dark_path = resolve(base_dir, *dark);
    dark_image = imaging::read_raw_image(dark_path);
    if (dark_image->width != first.width || dark_image->height != first.height) {
      throw Error(dark_path.string() + ": dark frame is " +
                  size_text(dark_image->width, dark_image->height) + " pixels but " +
                  stack.paths.front().string() + " is " + size_text(first.width, first.height));
    }
    if (dark_image->max_value != max_value || dark_image->black != first.black) {
      throw Error(dark_path.string() + ": dark frame is " + code_range(*dark_image) + " but " +
                  stack.paths.front().string() + " is " + code_range(first));
    }
  }
  HdrResult result = merge_stack(stack, used, dark_image);
  result.exposure_s = stack.exposure_s;
  result.iso_scaled = stack.iso_known;
  result.camera_raw = is_camera_raw(first);
  if (dark) result.sources.push_back(resolve(base_dir, *dark));
  return result;
}

}  // namespace lucent::acquire
