#include "lucent/imaging/camera_raw.h"

#include <fcntl.h>
#include <libraw/libraw.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <memory>
#include <mutex>
#include <set>

#include "lucent/core/error.h"
#include "lucent/core/json_file.h"

namespace lucent::imaging {
namespace {

// As for the other readers: at most 16384 x 16384 pixels out (a RAW sensor twice that).
constexpr long long kMaxSensorPixels = 4ll << 28;
constexpr int kMaxImageSide = 16384;
constexpr std::size_t kMaxRawFileBytes = std::size_t(1) << 30;

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return char(std::tolower(ch)); });
  return ext;
}

// LibRaw reports damaged data through a callback that prints by default: keep the first message
// for lucent's own error line instead.
void note_data_error(void* context, const char*, const int offset) {
  auto* message = static_cast<std::string*>(context);
  if (message->empty()) {
    *message =
        offset < 0 ? "unexpected end of file" : "corrupt data near byte " + std::to_string(offset);
  }
}

// The channel (0 R, 1 G, 2 B) of LibRaw's colour index, or -1 for a colour lucent cannot use.
int channel_of(const libraw_iparams_t& idata, int colour) {
  if (colour < 0 || colour > 3) return -1;
  switch (idata.cdesc[colour]) {
    case 'R':
      return 0;
    case 'G':
      return 1;
    case 'B':
      return 2;
    default:
      return -1;
  }
}

// Black level of the photosite at visible (row, col) of colour index `colour`: the common part,
// the per-colour part and the repeating pattern (LibRaw's cblack[4] x cblack[5] at cblack[6]).
double black_at(const libraw_colordata_t& color, int colour, int row, int col) {
  double black = double(color.black) + double(color.cblack[colour]);
  const unsigned rows = color.cblack[4], cols = color.cblack[5];
  if (rows > 0 && cols > 0) black += color.cblack[6 + (row % rows) * cols + (col % cols)];
  return black;
}

std::string camera_name(const libraw_iparams_t& idata) {
  std::string name = std::string(idata.make) + " " + std::string(idata.model);
  while (!name.empty() && name.back() == ' ') name.pop_back();
  return name.empty() ? "unknown camera" : name;
}

RawImage read_bayer(LibRaw& raw, const std::string& name) {
  const libraw_image_sizes_t& s = raw.imgdata.sizes;
  const libraw_iparams_t& idata = raw.imgdata.idata;
  const libraw_colordata_t& color = raw.imgdata.color;
  // A 2 x 2 mosaic repeats every two rows and columns: LibRaw's 8-row pattern must agree.
  for (int row = 0; row < 8; ++row) {
    for (int col = 0; col < 2; ++col) {
      if (raw.COLOR(row, col) != raw.COLOR(row % 2, col)) {
        throw Error(name +
                    ": the colour filter pattern does not repeat every 2 x 2 photosites "
                    "(lucent reads 2 x 2 Bayer sensors)");
      }
    }
  }
  if (color.cblack[4] > 2 || color.cblack[5] > 2) {
    throw Error(name + ": black-level pattern of " + std::to_string(color.cblack[4]) + " x " +
                std::to_string(color.cblack[5]) + " photosites (lucent supports up to 2 x 2)");
  }
  // Which photosite of the quad gives which channel, and each channel's black level.
  std::array<int, 4> channel{};
  std::array<int, 3> sites{};
  std::array<double, 3> black{};
  for (int q = 0; q < 4; ++q) {
    const int row = q / 2, col = q % 2, colour = raw.COLOR(row, col);
    channel[q] = channel_of(idata, colour);
    if (channel[q] < 0) {
      throw Error(name + ": colour filter '" + std::string(1, idata.cdesc[colour % 4]) +
                  "' is not red, green or blue (lucent reads RGB Bayer sensors)");
    }
    ++sites[channel[q]];
    black[channel[q]] += black_at(color, colour, row, col);
  }
  if (sites[0] != 1 || sites[1] != 2 || sites[2] != 1) {
    throw Error(name + ": the 2 x 2 quad is not one red, two green and one blue photosite");
  }
  for (int c = 0; c < 3; ++c) black[c] /= sites[c];

  const int w = s.width / 2, h = s.height / 2;
  const int white = int(std::min<unsigned>(color.maximum, 65535));
  RawImage image(w, h, white);
  image.black = black;
  const std::uint16_t* data = raw.imgdata.rawdata.raw_image;
  const std::size_t pitch = s.raw_pitch / sizeof(std::uint16_t);
  const auto code = [&](int row, int col) -> int {
    const int v = data[std::size_t(row + s.top_margin) * pitch + std::size_t(col + s.left_margin)];
    return std::min(v, white);
  };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      int green_sum = 0;
      bool green_saturated = false;
      for (int q = 0; q < 4; ++q) {
        const int v = code(2 * y + q / 2, 2 * x + q % 2);
        if (channel[q] == 1) {
          green_sum += v;
          green_saturated = green_saturated || v >= white - 1;
        } else {
          image.at(x, y, channel[q]) = std::uint16_t(v);
        }
      }
      image.at(x, y, 1) = std::uint16_t(green_saturated ? white : (green_sum + 1) / 2);
    }
  }
  return image;
}

// A linear DNG: three (or four, the fourth unused) samples per pixel, already interpolated by
// whatever wrote it.
RawImage read_linear(LibRaw& raw, const std::string& name) {
  const libraw_image_sizes_t& s = raw.imgdata.sizes;
  const libraw_colordata_t& color = raw.imgdata.color;
  const libraw_rawdata_t& rd = raw.imgdata.rawdata;
  const int samples = rd.color3_image ? 3 : 4;
  const std::uint16_t* data = rd.color3_image ? &rd.color3_image[0][0] : &rd.color4_image[0][0];
  const int white = int(std::min<unsigned>(color.maximum, 65535));
  if (s.width > kMaxImageSide || s.height > kMaxImageSide) {  // one pixel per photosite here
    throw Error(name + ": the linear DNG is larger than 16384 x 16384 pixels");
  }
  RawImage image(s.width, s.height, white);
  for (int c = 0; c < 3; ++c) {
    image.black[c] = black_at(color, c, 0, 0);
    if (color.cblack[4] > 1 || color.cblack[5] > 1) {
      throw Error(name + ": linear DNG with a black-level pattern (not supported)");
    }
  }
  const std::size_t pitch = s.raw_pitch / sizeof(std::uint16_t);
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      const std::uint16_t* px =
          data + std::size_t(y + s.top_margin) * pitch + std::size_t(x + s.left_margin) * samples;
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = std::uint16_t(std::min<int>(px[c], white));
    }
  }
  return image;
}

// The decoding itself, in whichever process runs it.
RawImage decode_in_this_process(std::string_view bytes, const std::string& name) {
  // LibRaw's object holds large buffers: on the heap, one per call (thread-safe libraw_r).
  auto raw = std::make_unique<LibRaw>(LIBRAW_OPTIONS_NONE);
  std::string data_error;
  raw->set_dataerror_handler(note_data_error, &data_error);
  const auto fail = [&](const std::string& what, int code) {
    std::string line = name + ": " + what;
    if (code != LIBRAW_SUCCESS) line += " (" + std::string(libraw_strerror(code)) + ")";
    if (!data_error.empty()) line += ": " + data_error;
    throw Error(line);
  };
  int rc = raw->open_buffer(const_cast<char*>(bytes.data()), bytes.size());
  if (rc != LIBRAW_SUCCESS) fail("not a camera RAW file LibRaw can read", rc);
  const libraw_image_sizes_t& s = raw->imgdata.sizes;
  if (s.width < 2 || s.height < 2) fail("RAW image has no pixels", LIBRAW_SUCCESS);
  if (static_cast<long long>(s.raw_width) * s.raw_height > kMaxSensorPixels) {
    fail("the RAW sensor is larger than 32768 x 32768 photosites", LIBRAW_SUCCESS);
  }
  rc = raw->unpack();
  if (rc != LIBRAW_SUCCESS) fail("cannot decode the RAW data", rc);
  if (!data_error.empty()) fail("damaged RAW data", LIBRAW_SUCCESS);

  const libraw_iparams_t& idata = raw->imgdata.idata;
  const libraw_colordata_t& color = raw->imgdata.color;
  const libraw_rawdata_t& rd = raw->imgdata.rawdata;
  if (color.maximum == 0 || color.maximum > 65535) {
    fail("no usable white level (maximum " + std::to_string(color.maximum) + ")", LIBRAW_SUCCESS);
  }
  RawImage image;
  if (rd.raw_image && idata.filters >= 1000) {
    image = read_bayer(*raw, name);
  } else if (!rd.raw_image && (rd.color3_image || rd.color4_image) && idata.colors == 3) {
    image = read_linear(*raw, name);
  } else {
    fail("sensor layout not supported (" + camera_name(idata) +
             (idata.filters == 9 ? ": X-Trans"
              : idata.filters    ? ": non-Bayer mosaic"
                                 : "") +
             "; lucent reads 2 x 2 RGB Bayer RAW files and linear DNGs)",
         LIBRAW_SUCCESS);
  }
  for (int c = 0; c < 3; ++c) {
    if (!(image.black[c] < image.max_value - 1)) {
      fail("black level " + std::to_string(image.black[c]) + " is not below the white level " +
               std::to_string(image.max_value),
           LIBRAW_SUCCESS);
    }
  }
  const libraw_imgother_t& other = raw->imgdata.other;
  if (other.shutter > 0 && std::isfinite(other.shutter)) image.metadata.exposure_s = other.shutter;
  if (other.iso_speed > 0 && std::isfinite(other.iso_speed)) image.metadata.iso = other.iso_speed;
  image.metadata.camera = camera_name(idata);
  return image;
}

}  // namespace

bool is_camera_raw_path(const std::filesystem::path& path) {
  static const std::set<std::string> kExtensions = {
      ".dng", ".cr2", ".cr3", ".crw", ".nef", ".nrw", ".arw", ".srf", ".sr2", ".raf", ".orf",
      ".rw2", ".pef", ".srw", ".3fr", ".iiq", ".erf", ".kdc", ".mos", ".mrw", ".x3f"};
  return kExtensions.count(lower_extension(path)) > 0;
}

namespace {

// --- LibRaw in a child process ---------------------------------------------------------------
// LibRaw parses hundreds of proprietary formats and has had memory bugs found by fuzzing (the
// Debian 0.20 build aborts in parseHassyModel on a crafted "Hasselblad" file, found by
// fuzz_camera_raw). A RAW file is untrusted input, so it is decoded in a forked child that sends
// the image back through a pipe: a crash or hang there becomes lucent's one error line, never a
// crash of lucent. The cost is one fork per file (copy-on-write; about a millisecond).

constexpr int kChildTimeoutSeconds = 120;

void append_bytes(std::string& out, const void* data, std::size_t size) {
  out.append(static_cast<const char*>(data), size);
}

std::string serialise(const RawImage& image) {
  std::string out(1, '\0');  // status 0: an image follows
  const std::int32_t header[3] = {image.width, image.height, image.max_value};
  append_bytes(out, header, sizeof header);
  append_bytes(out, image.black.data(), sizeof(double) * 3);
  const double exposure = image.metadata.exposure_s.value_or(-1.0);
  const double iso = image.metadata.iso.value_or(-1.0);
  append_bytes(out, &exposure, sizeof exposure);
  append_bytes(out, &iso, sizeof iso);
  const std::uint32_t camera_size = std::uint32_t(image.metadata.camera.size());
  append_bytes(out, &camera_size, sizeof camera_size);
  out += image.metadata.camera;
  append_bytes(out, image.data.data(), image.data.size() * sizeof(std::uint16_t));
  return out;
}

RawImage deserialise(const std::string& bytes, const std::string& name) {
  const auto broken = [&] { return Error(name + ": the RAW decoder's answer was cut short"); };
  std::size_t at = 1;
  const auto take = [&](void* out, std::size_t size) {
    if (bytes.size() < at + size) throw broken();
    std::memcpy(out, bytes.data() + at, size);
    at += size;
  };
  std::int32_t header[3];
  take(header, sizeof header);
  // Checked before anything is allocated: the child is the process that may have gone wrong.
  if (header[0] <= 0 || header[1] <= 0 || header[0] > kMaxImageSide || header[1] > kMaxImageSide ||
      header[2] <= 0 || header[2] > 65535) {
    throw broken();
  }
  const std::size_t pixels_bytes = std::size_t(header[0]) * std::size_t(header[1]) * 3 * 2;
  if (bytes.size() < at + pixels_bytes) throw broken();
  RawImage image(header[0], header[1], header[2]);
  take(image.black.data(), sizeof(double) * 3);
  double exposure, iso;
  take(&exposure, sizeof exposure);
  take(&iso, sizeof iso);
  if (exposure > 0) image.metadata.exposure_s = exposure;
  if (iso > 0) image.metadata.iso = iso;
  std::uint32_t camera_size;
  take(&camera_size, sizeof camera_size);
  if (bytes.size() < at + camera_size) throw broken();
  image.metadata.camera = bytes.substr(at, camera_size);
  at += camera_size;
  take(image.data.data(), image.data.size() * sizeof(std::uint16_t));
  if (at != bytes.size()) throw broken();
  return image;
}

bool write_all(int fd, const std::string& bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += std::size_t(n);
  }
  return true;
}

[[noreturn]] void run_child(int fd, std::string_view bytes, const std::string& name, pid_t parent) {
  // The CLI blocks SIGINT/SIGTERM/SIGHUP in every thread for its signal thread, which the child
  // does not have: unblocked, so that they end a child that hangs; and the child dies with the
  // parent (a Ctrl-C of lucent must not leave LibRaw spinning).
  sigset_t none;
  sigemptyset(&none);
  ::pthread_sigmask(SIG_SETMASK, &none, nullptr);
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) _exit(4);
  // A crash is the child's to die of: handlers the process installed (a sanitizer's, libFuzzer's)
  // would report it as lucent's own. The parent turns the signal into the error line.
  for (int sig : {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGILL}) ::signal(sig, SIG_DFL);
  // LibRaw's own prints (and a fortified abort's message) stay out of lucent's output.
  const int null = ::open("/dev/null", O_WRONLY);
  if (null >= 0) ::dup2(null, STDERR_FILENO), ::dup2(null, STDOUT_FILENO);
  std::string answer;
  try {
    answer = serialise(decode_in_this_process(bytes, name));
  } catch (const Error& e) {
    answer = std::string(1, '\1') + e.what();  // status 1: lucent's error line follows
  } catch (const std::exception& e) {
    answer = std::string(1, '\1') + name + ": the RAW decoder failed: " + e.what();
  }
  _exit(write_all(fd, answer) ? 0 : 3);
}

}  // namespace

RawImage decode_camera_raw(std::string_view bytes, const std::string& name) {
  // The child owns the pipe's write end alone: a fork by another thread between pipe2 and the
  // parent's close would keep a copy open, and this read would wait for that child instead.
  static std::mutex fork_mutex;
  std::unique_lock fork_lock(fork_mutex);
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) {
    throw Error(name + ": cannot start the RAW decoder (pipe: " + std::strerror(errno) + ")");
  }
  std::fflush(nullptr);
  const pid_t parent = ::getpid();
  const pid_t child = ::fork();
  if (child < 0) {
    const int error = errno;
    ::close(fds[0]), ::close(fds[1]);
    throw Error(name + ": cannot start the RAW decoder (fork: " + std::strerror(error) + ")");
  }
  if (child == 0) {
    ::close(fds[0]);
    run_child(fds[1], bytes, name, parent);
  }
  ::close(fds[1]);
  fork_lock.unlock();
  // Whatever happens here (a timeout, bad_alloc while reading), the pipe is closed and the child
  // killed if it still runs, and reaped.
  struct ChildGuard {
    int fd;
    pid_t pid;
    bool reaped = false;
    int status = 0;
    int wait() {
      if (fd >= 0) ::close(fd), fd = -1;
      while (!reaped && ::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      reaped = true;
      return status;
    }
    ~ChildGuard() {
      if (!reaped) ::kill(pid, SIGKILL);
      wait();
    }
  } guard{fds[0], child};

  std::string answer;
  char buffer[1 << 16];
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::seconds(kChildTimeoutSeconds);
  bool timed_out = false;
  for (;;) {
    const long long left = std::chrono::duration_cast<std::chrono::milliseconds>(
                               deadline - std::chrono::steady_clock::now())
                               .count();
    if (left <= 0) {
      timed_out = true;
      break;
    }
    pollfd p{guard.fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, int(std::min<long long>(left, 1 << 30)));
    if (ready < 0 && errno != EINTR) break;  // the answer so far decides (cut short: an error)
    if (ready <= 0) continue;                // EINTR, or the deadline: the loop's test decides
    const ssize_t n = ::read(guard.fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    answer.append(buffer, std::size_t(n));
  }
  if (timed_out) {
    ::kill(child, SIGKILL);
    guard.wait();
    throw Error(name + ": the RAW decoder (LibRaw) did not finish in " +
                std::to_string(kChildTimeoutSeconds) + " s; the file is damaged or crafted");
  }
  const int status = guard.wait();
  if (WIFSIGNALED(status)) {
    throw Error(name + ": the RAW decoder (LibRaw) crashed on this file (signal " +
                std::to_string(WTERMSIG(status)) + "); it is damaged or crafted, or LibRaw " +
                "cannot read it");
  }
  if (answer.empty()) {
    throw Error(name + ": the RAW decoder (LibRaw) gave no answer (exit status " +
                std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")");
  }
  if (answer[0] == '\1') throw Error(answer.substr(1));
  return deserialise(answer, name);
}

std::string camera_raw_decoder_version() {
  return std::string("LibRaw ") + LibRaw::version();
}

RawImage read_camera_raw(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) throw Error(path.string() + ": no such image file");
  const std::string bytes = read_input_file(path, kMaxRawFileBytes);
  return decode_camera_raw(bytes, path.string());
}

}  // namespace lucent::imaging
