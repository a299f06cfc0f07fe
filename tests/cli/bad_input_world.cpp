// The shared, valid inputs of the bad-input tables, made once per test binary from lucent's own
// files and commands (so that a case's refusal is the mutation's, not a broken fixture's).
#include <unistd.h>

#include <cstdint>
#include <cstring>

#include "bad_input.h"
#include "lucent/imaging/image_io.h"

namespace lucent::testing {
namespace {

void run_or_die(const std::string& args) {
  const CommandResult r = run_lucent(args, "world");
  if (r.exit_code != 0) {
    ADD_FAILURE() << "setting up the bad-input world: lucent " << args << " failed: " << r.err;
  }
}

// A Radiance .hdr with flat (uncompressed) scanlines.
void write_hdr(const fs::path& path, int width, int height, float value) {
  std::string bytes = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(height) +
                      " +X " + std::to_string(width) + "\n";
  int exponent = 0;
  const float mantissa = std::frexp(value, &exponent);
  const auto m = static_cast<unsigned char>(mantissa * 256.0f);
  for (int i = 0; i < width * height; ++i) {
    bytes += static_cast<char>(m);
    bytes += static_cast<char>(m);
    bytes += static_cast<char>(m);
    bytes += static_cast<char>(exponent + 128);
  }
  write_file(path, bytes);
}

// Built into a private folder, then renamed into place: ctest runs every case as its own process,
// so the first process builds the world and the others (in parallel too) reuse it. The name holds
// the lucent binary's modification time: a rebuilt lucent gets a new world.
// `final` is where `w` will be renamed to: the absolute paths written into files name it.
fs::path make_world_in(const fs::path& w, const fs::path& final) {
  fs::create_directories(w);
  const fs::path src = LUCENT_SOURCE_DIR;
  fs::copy_file(src / "materials/library/marble.json", w / "marble.json");
  fs::copy(src / "notebooks_data/captures/marble_0deg", w / "cap");
  fs::remove(w / "cap/truth.json");
  // The capture with absolute image paths, so that a case's copy may live in any folder.
  Json cap = read_json(w / "cap/capture.json");
  for (auto* images : {&cap["images"], &cap["white_reference"]["images"]}) {
    for (auto& image : *images)
      image["path"] = (final / "cap" / image["path"].get<std::string>()).string();
  }
  cap["dark"] = (final / "cap" / cap["dark"].get<std::string>()).string();
  write_file(w / "capture_abs.json", cap.dump(2));
  run_or_die("acquire \"" + (w / "cap/capture.json").string() + "\" -o \"" + (w / "acq").string() +
             "\" --bins 60");
  run_or_die("profile --material marble --r-range 0.1:10:40:log -o \"" +
             (w / "radial.csv").string() + "\"");
  fs::copy_file(src / "tests/cli/data/configs.csv", w / "configs.csv");
  for (const char* mesh : {"cube_ascii.ply", "cube_binary.ply", "cube.obj"})
    fs::copy_file(src / "fuzz/seeds/mesh" / mesh, w / mesh);
  imaging::ImageRgb env(16, 8, 0.5f);
  imaging::write_exr(w / "env.exr", env);
  write_hdr(w / "env.hdr", 16, 8, 0.5f);
  return w;
}

fs::path make_world() {
  const auto stamp = fs::last_write_time(LUCENT_BINARY).time_since_epoch().count();
  const fs::path w =
      fs::temp_directory_path() / ("lucent-bad-input-world-" + std::to_string(stamp));
  if (fs::exists(w / "complete")) return w;
  const fs::path mine = w.string() + ".building-" + std::to_string(::getpid());
  fs::remove_all(mine);
  make_world_in(mine, w);
  write_file(mine / "complete", "");
  std::error_code ec;
  fs::rename(mine, w, ec);  // fails when another process got there first: use theirs
  if (ec) fs::remove_all(mine);
  return w;
}

}  // namespace

const fs::path& world() {
  static const fs::path w = make_world();
  return w;
}

}  // namespace lucent::testing
