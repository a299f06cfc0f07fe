#include "lucent/imaging/image_io.h"

#include <Iex.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <cstdint>
#include <cmath>
#include <mutex>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/core/json_file.h"
#include "lucent/imaging/camera_raw.h"

namespace lucent::imaging {

namespace {

// Largest image lucent reads: 2^28 pixels (16384 x 16384), so that a header cannot make it
// allocate more than a few GiB.
constexpr long long kMaxPixels = 1ll << 28;

// libpng and libtiff print warnings on stderr themselves ("libpng warning: iCCP: ..."), and
// OpenCV logs its own; lucent's one error line must be all a user sees. OpenCV's log is silenced;
// the decoders' own prints are kept off stderr by pointing file descriptor 2 at /dev/null for the
// duration of the call (one call at a time).
class QuietStderr {
 public:
  QuietStderr() : lock_(mutex()) {
    std::fflush(stderr);
    saved_ = ::dup(2);
    const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_ >= 0 && null >= 0) ::dup2(null, 2);
    if (null >= 0) ::close(null);
  }
  ~QuietStderr() {
    std::fflush(stderr);
    if (saved_ >= 0) {
      ::dup2(saved_, 2);
      ::close(saved_);
    }
  }
  QuietStderr(const QuietStderr&) = delete;
  QuietStderr& operator=(const QuietStderr&) = delete;

 private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  std::lock_guard<std::mutex> lock_;
  int saved_ = -1;
};

// The formats lucent reads through OpenCV, by their first bytes: PNG and TIFF brackets, Radiance
// .hdr maps. Nothing else reaches OpenCV, which sniffs the bytes and hands them to whatever codec
// claims them (a fuzzed "PNG" went to the DICOM reader, which aborts on bad input).
bool known_signature(const std::string& b, bool radiance) {
  const auto starts = [&](const char* s, std::size_t n) { return b.size() >= n && b.compare(0, n, s, n) == 0; };
  if (radiance) return starts("#?RADIANCE", 10) || starts("#?RGBE", 6);
  return starts("\x89PNG\r\n\x1a\n", 8) || starts("II*\0", 4) || starts("MM\0*", 4);
}

cv::Mat decode_image_quietly(const std::filesystem::path& path, int flags, bool radiance) {
  static const bool silenced = [] {
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    return true;
  }();
  (void)silenced;
  // Read by lucent (bounded, recorded as an input), decoded from memory by OpenCV.
  const std::string bytes = read_input_file(path, std::size_t(1) << 30);
  if (!known_signature(bytes, radiance))
    return cv::Mat();  // the callers name the file and what they expected
  // A PNG's size is in its header: judged before the decoder allocates for it (a 1.2 MB PNG of
  // 20000^2 was decoded whole, 1.2 GB, before the check below).
  if (bytes.size() >= 24 && bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0 &&
      bytes.compare(12, 4, "IHDR") == 0) {
    const auto be32 = [&](std::size_t at) {
      return (std::uint32_t(std::uint8_t(bytes[at])) << 24) |
             (std::uint32_t(std::uint8_t(bytes[at + 1])) << 16) |
             (std::uint32_t(std::uint8_t(bytes[at + 2])) << 8) | std::uint32_t(std::uint8_t(bytes[at + 3]));
    };
    const long long w = be32(16), h = be32(20);
    if (w > 16384 || h > 16384 || w * h > kMaxPixels)
      throw Error(path.string() + ": the PNG's header says " + std::to_string(w) + " x " +
                  std::to_string(h) + " pixels, larger than 16384 x 16384");
  }
  const cv::Mat buffer(1, static_cast<int>(bytes.size()), CV_8U, const_cast<char*>(bytes.data()));
  cv::Mat mat;
  try {
    QuietStderr quiet;
    mat = cv::imdecode(buffer, flags);
  } catch (const cv::Exception&) {
    mat.release();
  }
  if (!mat.empty() && static_cast<long long>(mat.cols) * mat.rows > kMaxPixels) {
    throw Error(path.string() + ": the image is larger than 16384 x 16384 pixels");
  }
  return mat;
}

}  // namespace

ImageRgb read_radiance_hdr(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) throw Error(path.string() + ": no such image file");
  const cv::Mat bgr = decode_image_quietly(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_COLOR, true);
  if (bgr.empty()) throw Error(path.string() + ": not a readable Radiance .hdr image");
  if (bgr.depth() != CV_32F || bgr.channels() != 3) {
    throw Error(path.string() + ": not a floating-point (HDR) image");
  }
  ImageRgb image(bgr.cols, bgr.rows);
  for (int y = 0; y < bgr.rows; ++y) {
    const cv::Vec3f* row = bgr.ptr<cv::Vec3f>(y);
    for (int x = 0; x < bgr.cols; ++x) {
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = row[x][2 - c];  // BGR -> RGB
    }
  }
  return image;
}

ImageRgb read_exr(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path))
    throw Error(path.string() + ": no such file (expected an OpenEXR image)");
  if (!std::filesystem::is_regular_file(path))
    throw Error(path.string() + ": not a regular file (expected an OpenEXR image)");
  note_input(path);
  {
    // OpenEXR's own word for another format is "File is not an image file".
    std::ifstream in(path, std::ios::binary);
    char magic[4] = {};
    in.read(magic, 4);
    if (!in || std::string(magic, 4) != std::string("\x76\x2f\x31\x01", 4))
      throw Error(path.string() + ": not an OpenEXR image (expected a linear .exr file)");
  }
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i window = file.header().dataWindow();
    const long long width = static_cast<long long>(window.max.x) - window.min.x + 1;
    const long long height = static_cast<long long>(window.max.y) - window.min.y + 1;
    if (width <= 0 || height <= 0) throw Error(path.string() + ": empty OpenEXR image");
    if (width > 16384 || height > 16384 || width * height > kMaxPixels)
      throw Error(path.string() + ": the OpenEXR image is larger than 16384 x 16384 pixels");
    // What the header claims against the bytes there: no codec packs float pixels 4096 to 1 (an
    // 11.6 KB file claiming 16384^2 pixels drove memory to 3.2 GB).
    std::error_code ec;
    const auto bytes = std::filesystem::file_size(path, ec);
    if (!ec && double(width) * double(height) * 12 > 4096.0 * double(bytes))
      throw Error(path.string() + ": the OpenEXR header claims " + std::to_string(width) + " x " +
                  std::to_string(height) + " pixels in " + std::to_string(bytes) +
                  " bytes: not an image lucent reads (truncated or forged)");
    const Imf::ChannelList& channels = file.header().channels();
    const bool rgb =
        channels.findChannel("R") && channels.findChannel("G") && channels.findChannel("B");
    const bool grey = channels.findChannel("Y") != nullptr;
    if (!rgb && !grey)
      throw Error(path.string() + ": OpenEXR image has neither R, G, B nor Y channels");
    ImageRgb image(width, height);
    Imf::FrameBuffer frame;
    const std::size_t xs = sizeof(float) * 3, ys = xs * width;
    char* base = reinterpret_cast<char*>(image.data.data()) -
                 (std::ptrdiff_t(window.min.x) * xs + std::ptrdiff_t(window.min.y) * ys);
    // R, G, B as they are; a luminance image (Y alone) is grey: Y in all three (a frame buffer
    // holds one slice per name, so Y goes into red and is copied: inserted three times it filled
    // blue alone).
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < (rgb ? 3 : 1); ++c) {
      frame.insert(rgb ? names[c] : "Y",
                   Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys, 1, 1, 0.0));
    }
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
    if (!rgb)
      for (std::size_t i = 0; i < image.data.size(); i += 3)
        image.data[i + 1] = image.data[i + 2] = image.data[i];
    return image;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    std::string what = e.what();
    std::replace(what.begin(), what.end(), '\n', ' ');
    throw Error(path.string() + ": cannot read as OpenEXR: " + what);
  }
}

void write_exr(const std::filesystem::path& path, const ImageRgb& image,
               const std::map<std::string, std::string>& attributes) {
  if (image.width <= 0 || image.height <= 0)
    throw Error(path.string() + ": refusing to write an empty image");
  for (std::size_t i = 0; i < image.data.size(); ++i) {
    if (!std::isfinite(image.data[i])) {
      const std::size_t pixel = i / 3;
      throw Error(path.string() + ": cannot write: pixel (" +
                  std::to_string(pixel % std::size_t(image.width)) + ", " +
                  std::to_string(pixel / std::size_t(image.width)) +
                  ") is not finite (lucent writes only finite values)");
    }
  }
  AtomicOutputPath out(path);
  try {
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const char* name : {"R", "G", "B"})
      header.channels().insert(name, Imf::Channel(Imf::FLOAT));
    for (const auto& [key, value] : attributes) header.insert(key, Imf::StringAttribute(value));
    Imf::OutputFile file(out.temporary().c_str(), header);
    Imf::FrameBuffer frame;
    const std::size_t xs = sizeof(float) * 3, ys = xs * image.width;
    char* base = reinterpret_cast<char*>(const_cast<float*>(image.data.data()));
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
      frame.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
    }
    file.setFrameBuffer(frame);
    file.writePixels(image.height);
  } catch (const std::exception& e) {
    throw Error(path.string() + ": cannot write OpenEXR: " + e.what());
  }
  out.commit();
}

RawImage read_raw_image(const std::filesystem::path& path) {
  if (is_camera_raw_path(path)) return read_camera_raw(path);
  if (!std::filesystem::exists(path)) throw Error(path.string() + ": no such image file");
  const cv::Mat mat = decode_image_quietly(path, cv::IMREAD_UNCHANGED, false);
  if (mat.empty())
    throw Error(path.string() +
                ": cannot read as an image (expected PNG, TIFF or a camera RAW file)");
  int max_value = 0;
  if (mat.depth() == CV_8U)
    max_value = 255;
  else if (mat.depth() == CV_16U)
    max_value = 65535;
  else
    throw Error(path.string() + ": expected 8- or 16-bit integer pixels");
  cv::Mat rgb;
  switch (mat.channels()) {
    case 1:
      cv::cvtColor(mat, rgb, cv::COLOR_GRAY2RGB);
      break;
    case 3:
      cv::cvtColor(mat, rgb, cv::COLOR_BGR2RGB);
      break;
    case 4:
      cv::cvtColor(mat, rgb, cv::COLOR_BGRA2RGB);
      break;
    default:
      throw Error(path.string() + ": expected 1, 3 or 4 channels");
  }
  RawImage image(rgb.cols, rgb.rows, max_value);
  for (int y = 0; y < rgb.rows; ++y) {
    for (int x = 0; x < rgb.cols; ++x) {
      for (int c = 0; c < 3; ++c) {
        image.at(x, y, c) =
            max_value == 255 ? rgb.at<cv::Vec3b>(y, x)[c] : rgb.at<cv::Vec3w>(y, x)[c];
      }
    }
  }
  return image;
}

void write_png(const std::filesystem::path& path, const RawImage& image) {
  if (image.max_value != 255 && image.max_value != 65535) {
    throw Error(path.string() + ": PNG needs 8 or 16 bits (max value 255 or 65535)");
  }
  const bool eight = image.max_value == 255;
  cv::Mat mat(image.height, image.width, eight ? CV_8UC3 : CV_16UC3);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      for (int c = 0; c < 3; ++c) {  // OpenCV stores BGR
        if (eight)
          mat.at<cv::Vec3b>(y, x)[2 - c] = static_cast<std::uint8_t>(image.at(x, y, c));
        else
          mat.at<cv::Vec3w>(y, x)[2 - c] = image.at(x, y, c);
      }
    }
  }
  AtomicOutputPath out(path);
  bool ok = false;
  try {
    ok = cv::imwrite(out.temporary().string(), mat, {cv::IMWRITE_PNG_COMPRESSION, 9});
  } catch (const cv::Exception& e) {
    throw Error(path.string() + ": cannot write PNG: " + e.what());
  }
  if (!ok) throw Error(path.string() + ": cannot write PNG");
  out.commit();
}

ImageRgb read_any_image(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return std::tolower(ch); });
  if (ext == ".exr") return read_exr(path);
  const RawImage raw = read_raw_image(path);
  ImageRgb image(raw.width, raw.height);
  for (std::size_t i = 0; i < raw.data.size(); ++i) {
    const double black = raw.black[i % 3];
    image.data[i] = float((raw.data[i] - black) / (raw.max_value - black));
  }
  return image;
}

}  // namespace lucent::imaging
