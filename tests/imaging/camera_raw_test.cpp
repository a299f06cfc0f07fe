// Camera RAW through LibRaw, on DNGs this test writes with write_dng (libtiff): every value read
// back is known photosite by photosite, so the reader's quad binning, black and white levels and
// metadata are checked against the file's contents, not against LibRaw's own processing.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "lucent/core/error.h"
#include "lucent/imaging/camera_raw.h"
#include "lucent/imaging/image_io.h"

namespace lucent::imaging {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "lucent_camera_raw_test";
  fs::create_directories(dir);
  return dir / name;
}

// A mosaic whose code at (x, y) is a function of position and colour, inside (black, white). At
// least 22 x 22 photosites: LibRaw (as dcraw) refuses smaller sensors.
BayerMosaic test_mosaic(int w, int h, std::array<int, 4> pattern, int black, int white) {
  BayerMosaic m;
  m.width = w, m.height = h, m.pattern = pattern;
  m.black_level = black, m.white_level = white;
  m.data.resize(std::size_t(w) * h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int colour = pattern[(y % 2) * 2 + x % 2];
      m.data[std::size_t(y) * w + x] = std::uint16_t(black + 10 + 37 * x + 101 * y + 1000 * colour);
    }
  }
  return m;
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(CameraRaw, RecognisesRawExtensions) {
  for (const char* name : {"a.dng", "b.CR2", "c.cr3", "d.NEF", "e.arw", "f.Raf", "g.rw2"})
    EXPECT_TRUE(is_camera_raw_path(name)) << name;
  for (const char* name : {"a.png", "b.tif", "c.tiff", "d.exr", "dng", "e.dng.png"})
    EXPECT_FALSE(is_camera_raw_path(name)) << name;
}

// Each quad gives R and B from their photosites and G as the rounded mean of its two greens, for
// every 2 x 2 arrangement; black, white, exposure time and ISO come from the file.
TEST(CameraRaw, QuadsLevelsAndMetadataFromTheFile) {
  const std::array<std::array<int, 4>, 4> patterns{
      {{0, 1, 1, 2}, {2, 1, 1, 0}, {1, 0, 2, 1}, {1, 2, 0, 1}}};
  for (const auto& pattern : patterns) {
    BayerMosaic m = test_mosaic(48, 32, pattern, 512, 15000);
    m.exposure_s = 1.0 / 125;
    m.iso = 200;
    const fs::path path = scratch("quads.dng");
    write_dng(path, m);
    const RawImage image = read_raw_image(path);  // dispatches on the extension
    ASSERT_EQ(image.width, 24);
    ASSERT_EQ(image.height, 16);
    EXPECT_EQ(image.max_value, 15000);
    for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(image.black[c], 512.0) << c;
    ASSERT_TRUE(image.metadata.exposure_s.has_value());
    EXPECT_NEAR(*image.metadata.exposure_s, 1.0 / 125, 1e-7);
    ASSERT_TRUE(image.metadata.iso.has_value());
    EXPECT_DOUBLE_EQ(*image.metadata.iso, 200.0);
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        int expected[3] = {0, 0, 0}, greens = 0;
        for (int q = 0; q < 4; ++q) {
          const int sx = 2 * x + q % 2, sy = 2 * y + q / 2, colour = pattern[q];
          const int v = m.data[std::size_t(sy) * m.width + sx];
          if (colour == 1) {
            expected[1] += v, ++greens;
          } else {
            expected[colour] = v;
          }
        }
        ASSERT_EQ(greens, 2);
        expected[1] = (expected[1] + 1) / 2;
        for (int c = 0; c < 3; ++c) {
          ASSERT_EQ(image.at(x, y, c), expected[c])
              << "pattern " << pattern[0] << pattern[1] << pattern[2] << pattern[3] << " pixel "
              << x << "," << y << " channel " << c;
        }
      }
    }
  }
}

TEST(CameraRaw, NoMetadataWhenTheFileHasNone) {
  const fs::path path = scratch("bare.dng");
  write_dng(path, test_mosaic(24, 24, {0, 1, 1, 2}, 0, 65535));
  const RawImage image = read_camera_raw(path);
  EXPECT_FALSE(image.metadata.exposure_s.has_value());
  EXPECT_FALSE(image.metadata.iso.has_value());
  EXPECT_EQ(image.max_value, 65535);
  EXPECT_DOUBLE_EQ(image.black[0], 0.0);
}

// One saturated green makes the quad's green saturated (its mean would look unsaturated).
TEST(CameraRaw, OneSaturatedGreenSaturatesTheQuad) {
  BayerMosaic m = test_mosaic(24, 24, {0, 1, 1, 2}, 100, 6000);
  m.data[1] = 6000;  // photosite (1, 0): green of quad (0, 0)
  const fs::path path = scratch("saturated.dng");
  write_dng(path, m);
  const RawImage image = read_camera_raw(path);
  EXPECT_EQ(image.at(0, 0, 1), 6000);
  EXPECT_LT(image.at(1, 0, 1), 5999);
}

// Linear light from read_any_image: (v - black) / (white - black).
TEST(CameraRaw, LinearValuesSubtractTheBlackLevel) {
  BayerMosaic m = test_mosaic(24, 24, {0, 1, 1, 2}, 1000, 9000);
  m.data[0] = 5000;  // red of quad (0, 0): half way between black and white
  const fs::path path = scratch("linear.dng");
  write_dng(path, m);
  const ImageRgb linear = read_any_image(path);
  EXPECT_NEAR(linear.at(0, 0, 0), 0.5, 1e-6);
}

TEST(CameraRaw, DamagedFilesGiveOneLineNamingTheFile) {
  const fs::path good = scratch("good.dng");
  write_dng(good, test_mosaic(64, 64, {0, 1, 1, 2}, 64, 16383));
  std::ifstream in(good, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});

  const fs::path noise = scratch("noise.dng");
  {
    std::mt19937 rng(7);
    std::ofstream out(noise, std::ios::binary);
    for (int i = 0; i < 4096; ++i) out.put(char(rng() & 0xff));
  }
  const fs::path empty = scratch("empty.nef");
  std::ofstream(empty, std::ios::binary).close();
  const fs::path missing = scratch("missing.cr2");
  fs::remove(missing);

  for (const fs::path& path : {noise, empty, missing}) {
    const std::string message = message_of([&] { read_camera_raw(path); });
    EXPECT_NE(message.find(path.string()), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  // Every truncation of a valid file is an error or a smaller valid image, never a crash.
  for (std::size_t keep : {std::size_t(8), std::size_t(200), bytes.size() / 2, bytes.size() - 1}) {
    try {
      const RawImage image = decode_camera_raw(std::string_view(bytes).substr(0, keep), "cut.dng");
      EXPECT_EQ(image.data.size(), std::size_t(image.width) * image.height * 3);
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("cut.dng"), std::string::npos) << e.what();
    }
  }
}

// tests/imaging/data/libraw_0.20_abort.dng: 2.7 KB that a libFuzzer run of LibRaw's open_buffer
// and unpack (seeded with fuzz/seeds/raw) turned into a file LibRaw 0.20 aborts on (a fortified
// strcat overflow in its Hasselblad model parser). lucent decodes RAW in a child process: the
// abort is one error line, and this test process lives on to read a good file after it.
TEST(CameraRaw, ADecoderCrashIsOneErrorLineNotACrash) {
  const fs::path crafted = fs::path(LUCENT_TEST_DATA_DIR) / "data" / "libraw_0.20_abort.dng";
  ASSERT_TRUE(fs::exists(crafted));
  std::string message;
  try {
    const RawImage image = read_camera_raw(crafted);
    // A LibRaw that no longer crashes may read something: then it must be self-consistent.
    EXPECT_EQ(image.data.size(), std::size_t(image.width) * image.height * 3);
  } catch (const Error& e) {
    message = e.what();
  }
  if (camera_raw_decoder_version().rfind("LibRaw 0.20", 0) == 0) {
    EXPECT_NE(message.find("crashed on this file (signal"), std::string::npos) << message;
  }
  if (!message.empty()) {
    EXPECT_NE(message.find(crafted.string()), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  const fs::path good = scratch("after_crash.dng");
  write_dng(good, test_mosaic(32, 32, {0, 1, 1, 2}, 64, 4095));
  EXPECT_EQ(read_camera_raw(good).width, 16);
}

TEST(CameraRaw, WriterRefusesImpossibleMosaics) {
  BayerMosaic odd = test_mosaic(4, 4, {0, 1, 1, 2}, 10, 100);
  odd.width = 3;
  EXPECT_THROW(write_dng(scratch("odd.dng"), odd), Error);
  BayerMosaic levels = test_mosaic(4, 4, {0, 1, 1, 2}, 10, 100);
  levels.black_level = 200;
  EXPECT_THROW(write_dng(scratch("levels.dng"), levels), Error);
  EXPECT_FALSE(fs::exists(scratch("levels.dng")));
}

}  // namespace
}  // namespace lucent::imaging
