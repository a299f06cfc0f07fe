// Hostile and careless inputs, one table per class (issue "Nothing lost, nothing trusted
// blindly"): transport tables checked field by field beyond their checksum, images, impossible or
// contradictory physics, names that are data in every export. Batches, merges and the cache:
// hostile_runs_test.cpp. Each refusal: exit 1 or 2, one stderr line naming the culprit, nothing
// written, no temporary, no input changed, bounded memory and time (bad_input.h).
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>
#include <zlib.h>

#include <cstdio>
#include <cstdlib>

#include "bad_input.h"
#include "lucent/materials/transport_table.h"

namespace lucent::testing {
namespace {

// ---- transport tables ---------------------------------------------------------------------------

// The shipped radial table, its header edited and/or its payload edited (the checksum recomputed:
// a table "right by its checksum" with wrong contents).
std::function<void(const fs::path&)> table(std::function<void(nlohmann::json&)> edit_header,
                                           std::function<void(std::string&, const nlohmann::json&)>
                                               edit_payload = nullptr) {
  return [=](const fs::path& dir) {
    const std::string file =
        read_bytes(fs::path(LUCENT_SOURCE_DIR) / "materials" / "tables" / "transport.lut");
    const std::size_t nl = file.find('\n');
    nlohmann::json h = nlohmann::json::parse(file.substr(0, nl));
    std::string payload = file.substr(nl + 1);
    if (edit_payload) {
      edit_payload(payload, h);
      h["crc32"] = crc32(0L, reinterpret_cast<const Bytef*>(payload.data()), uInt(payload.size()));
    }
    if (edit_header) edit_header(h);
    write_file(dir / "t.lut", h.dump() + "\n" + payload);
  };
}

// Offsets in the first slice's payload: per quantity float32 values then uint8 codes, then the
// float64 totals and their standard errors.
std::size_t entries_of(const nlohmann::json& h) {
  const auto& g = h["grid"];
  return g["u"].size() * std::size_t(g.value("phi_bins", 1)) * std::size_t(g["rho_bins"].get<int>());
}

template <class T>
void poke(std::string& payload, std::size_t at, T v) {
  std::memcpy(payload.data() + at, &v, sizeof v);
}

std::vector<BadCase> table_cases() {
  const std::string fit = "fit {world}/acq/profile.json --table {dir}/t.lut -o {dir}/m.json";
  const auto totals_at = [](const nlohmann::json& h) { return 2 * entries_of(h) * 5; };
  return {
      {"zero_radius_bins",
       table([](nlohmann::json& h) { h["grid"]["rho_max"] = h["grid"]["rho_min"].get<double>() * 1.0001; }),
       fit, "t.lut: grid"},
      {"one_radius_bin",
       table([](nlohmann::json& h) {
         h["grid"]["rho_max"] = h["grid"]["rho_min"].get<double>() * 1.1;
         h["grid"]["rho_per_decade"] = 10;
       }),
       fit, "t.lut"},
      {"rho_range_huge", table([](nlohmann::json& h) { h["grid"]["rho_max"] = 1e300; }), fit, "t.lut"},
      {"rho_min_negative", table([](nlohmann::json& h) { h["grid"]["rho_min"] = -1; }), fit, "t.lut: grid"},
      {"rho_per_decade_zero", table([](nlohmann::json& h) { h["grid"]["rho_per_decade"] = 0; }), fit,
       "t.lut: grid"},
      {"groups_one", table([](nlohmann::json& h) { h["groups"] = 1; }), fit, "t.lut: grid"},
      {"u_not_rising",
       table([](nlohmann::json& h) { std::swap(h["grid"]["u"][1], h["grid"]["u"][2]); }), fit, "t.lut: grid"},
      {"u_reaches_one", table([](nlohmann::json& h) { h["grid"]["u"].back() = 1.0; }), fit, "t.lut: grid"},
      {"u_grid_larger_than_the_payload",
       table([](nlohmann::json& h) {
         auto& u = h["grid"]["u"];
         for (int k = 1; k < 3000; ++k) u.push_back(u.back().get<double>() + (1 - u.back().get<double>()) * 1e-3);
       }),
       fit, "t.lut: payload_bytes"},
      {"no_slices", table([](nlohmann::json& h) { h["slices"] = nlohmann::json::array(); }), fit,
       "t.lut: slices"},
      {"slice_eta_half", table([](nlohmann::json& h) { h["slices"][0]["eta"] = 0.5; }), fit, "t.lut: slices"},
      {"payload_bytes_lie", table([](nlohmann::json& h) { h["payload_bytes"] = 8ull << 30; }), fit,
       "t.lut: payload_bytes"},
      {"max_path_negative", table([](nlohmann::json& h) { h["max_path"] = -1; }), fit, "t.lut: grid"},
      {"crc_wrong", table([](nlohmann::json& h) { h["crc32"] = 12345; }), fit, "t.lut: crc32"},
      {"total_nan",
       table(nullptr, [&](std::string& p, const nlohmann::json& h) {
         poke(p, totals_at(h), std::numeric_limits<double>::quiet_NaN());
       }),
       fit, "t.lut: totals"},
      {"total_negative",
       table(nullptr, [&](std::string& p, const nlohmann::json& h) { poke(p, totals_at(h), -0.5); }),
       fit, "t.lut: totals"},
      {"value_zero", table(nullptr, [](std::string& p, const nlohmann::json&) { poke(p, 0, 0.0f); }),
       fit, "t.lut: values"},
      {"value_infinite",
       table(nullptr, [](std::string& p, const nlohmann::json&) {
         poke(p, 16, std::numeric_limits<float>::infinity());
       }),
       fit, "t.lut: values"},
      {"header_not_json", bytes_file("t.lut", "{not json\n"), fit, "t.lut"},
      {"empty_file", bytes_file("t.lut", ""), fit, "t.lut"},
      {"an_oblique_table", nullptr,
       "fit {world}/acq/profile.json --table " LUCENT_SOURCE_DIR "/materials/tables/oblique.lut -o "
       "{dir}/m.json",
       "an oblique (2D) table"},
      {"a_shard",
       table([](nlohmann::json& h) {
         h["kind"] = "partial";
         h["partial_groups"] = nlohmann::json::array();
       }),
       fit, "t.lut: payload_bytes"},
  };
}

class TransportTables : public ::testing::TestWithParam<BadCase> {};
TEST_P(TransportTables, AreCheckedBeyondTheirChecksum) { expect_clean_refusal(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Table, TransportTables, ::testing::ValuesIn(table_cases()),
                         [](const auto& info) { return info.param.name; });

// ---- images ---------------------------------------------------------------------------------------

// An EXR of w x h pixels with these channels ("RGB" or "Y"), each pixel's values from `value`.
void write_exr_of(const fs::path& path, int w, int h, const std::string& channels,
                  const std::function<float(int x, int y, int c)>& value) {
  Imf::Header header(w, h);
  for (const char ch : channels) header.channels().insert(std::string(1, ch), Imf::Channel(Imf::FLOAT));
  const std::size_t n = channels.size();
  std::vector<float> v(std::size_t(w) * h * n);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (std::size_t c = 0; c < n; ++c) v[(std::size_t(y) * w + x) * n + c] = value(x, y, int(c));
  Imf::OutputFile file(path.c_str(), header);
  Imf::FrameBuffer frame;
  for (std::size_t c = 0; c < n; ++c)
    frame.insert(std::string(1, channels[c]),
                 Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(v.data() + c), sizeof(float) * n,
                            sizeof(float) * n * std::size_t(w)));
  file.setFrameBuffer(frame);
  file.writePixels(h);
}

std::function<void(const fs::path&)> two_exrs(
    std::function<float(int, int, int)> image, std::function<float(int, int, int)> reference,
    int w = 8, int reference_w = 8) {
  return [=](const fs::path& dir) {
    write_exr_of(dir / "a.exr", w, 8, "RGB", image);
    write_exr_of(dir / "b.exr", reference_w, 8, "RGB", reference);
  };
}

std::vector<BadCase> compare_cases() {
  const std::string cmp = "compare {dir}/a.exr {dir}/b.exr";
  const auto one = [](int, int, int) { return 1.0f; };
  return {
      {"image_nan", two_exrs([](int x, int, int) { return x == 3 ? NAN : 1.0f; }, one), cmp,
       "a.exr: pixel (3, 0) is not finite"},
      {"image_infinite", two_exrs([](int x, int y, int) { return x + y == 5 ? INFINITY : 1.0f; }, one),
       cmp, "a.exr: pixel"},
      {"image_negative", two_exrs([](int, int y, int) { return y == 2 ? -1.0f : 1.0f; }, one), cmp,
       "a.exr: pixel (0, 2) is negative"},
      {"reference_nan", two_exrs(one, [](int, int, int c) { return c == 1 ? NAN : 1.0f; }), cmp,
       "b.exr: pixel"},
      {"reference_negative", two_exrs(one, [](int, int, int) { return -2.0f; }), cmp,
       "b.exr: pixel"},
      {"reference_black", two_exrs(one, [](int, int, int) { return 0.0f; }), cmp,
       "b.exr: the reference is black"},
      {"sizes_differ", two_exrs(one, one, 8, 9), cmp, "a.exr: 8 x 8 pixels"},
      {"a_png_as_the_image",
       [](const fs::path& dir) {
         write_file(dir / "a.exr", "\x89PNG\r\n\x1a\nnot really");
         write_exr_of(dir / "b.exr", 8, 8, "RGB", [](int, int, int) { return 1.0f; });
       },
       cmp, "a.exr: not an OpenEXR image"},
      {"scale_nan", two_exrs(one, one), cmp + " --difference {dir}/d.png --scale nan", "--scale"},
      {"scale_negative", two_exrs(one, one), cmp + " --difference {dir}/d.png --scale -5",
       "--scale"},
      {"scale_zero", two_exrs(one, one), cmp + " --difference {dir}/d.png --scale 0", "--scale"},
      {"image_empty_file",
       [](const fs::path& dir) {
         write_file(dir / "a.exr", "");
         write_exr_of(dir / "b.exr", 8, 8, "RGB", [](int, int, int) { return 1.0f; });
       },
       cmp, "a.exr"},
      {"image_a_folder",
       [](const fs::path& dir) {
         fs::create_directory(dir / "a.exr");
         write_exr_of(dir / "b.exr", 8, 8, "RGB", [](int, int, int) { return 1.0f; });
       },
       cmp, "a.exr"},
      {"image_missing",
       [](const fs::path& dir) {
         write_exr_of(dir / "b.exr", 8, 8, "RGB", [](int, int, int) { return 1.0f; });
       },
       cmp, "a.exr"},
      {"image_z_only",
       [](const fs::path& dir) {
         write_exr_of(dir / "a.exr", 8, 8, "Z", [](int, int, int) { return 1.0f; });
         write_exr_of(dir / "b.exr", 8, 8, "RGB", [](int, int, int) { return 1.0f; });
       },
       cmp, "a.exr: OpenEXR image has neither"},
  };
}

class CompareImages : public ::testing::TestWithParam<BadCase> {};
TEST_P(CompareImages, AreRefusedCleanly) { expect_clean_refusal(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Table, CompareImages, ::testing::ValuesIn(compare_cases()),
                         [](const auto& info) { return info.param.name; });

// A luminance-only EXR (Y) is grey: Y in R, G and B (it was read into blue alone: acquire wrote
// R = G = 0, a grey environment lit the object blue). Compared with the RGB image of the same
// values: relative RMSE 0, every channel's mean ratio 1.
TEST(Images, ALuminanceOnlyExrIsGrey) {
  const fs::path dir = scratch_dir("hostile-y-exr");
  const auto value = [](int x, int y, int) { return 0.25f + 0.01f * float(x + 3 * y); };
  write_exr_of(dir / "y.exr", 8, 8, "Y", value);
  write_exr_of(dir / "rgb.exr", 8, 8, "RGB", value);
  const CommandResult r = run_lucent("compare \"" + (dir / "y.exr").string() + "\" \"" +
                                     (dir / "rgb.exr").string() + "\" --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["relative_rmse"].get<double>(), 0.0, 1e-7);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(j["mean_ratio"][c].get<double>(), 1.0, 1e-7) << c;
  fs::remove_all(dir);
}

// ---- impossible or contradictory physics --------------------------------------------------------

// The world's capture (absolute paths) with `edit` applied, as c.json in the case folder.
std::function<void(const fs::path&)> capture_edited(std::function<void(Json&)> edit) {
  return edited_json("capture_abs.json", "c.json", std::move(edit));
}

// A radial CSV of these rows ("r,value,se" each), with these comment tokens.
std::function<void(const fs::path&)> csv(std::string comments, std::string rows,
                                         std::string name = "p.csv") {
  return [=](const fs::path& dir) {
    write_file(dir / name, "# quantity=exitance " + comments + "\nr_mm,R,se\n" + rows);
  };
}

std::string rows_of(double value) {
  std::string rows;
  for (int i = 1; i <= 30; ++i) {
    char line[96];
    std::snprintf(line, sizeof line, "%g,%g,%g\n", 0.2 * i, value * std::exp(-0.3 * 0.2 * i) / (0.2 * i),
                  0.02 * value * std::exp(-0.3 * 0.2 * i) / (0.2 * i));
    rows += line;
  }
  return rows;
}

std::vector<BadCase> physics_cases() {
  const std::string fit = "fit {dir}/p.csv -o {dir}/m.json";
  const std::string acq = "acquire {dir}/c.json -o {dir}/out";
  return {
      {"ior_and_eta_disagree", csv("ior=1.3 eta=1.5", rows_of(0.1)), fit, "p.csv: comment fields ior= and eta= disagree"},
      {"a_row_twice", csv("ior=1.3", "1,0.1,0.001\n1,0.1,0.001\n2,0.05,0.001\n"), fit,
       "p.csv: line"},
      {"rows_falling_in_radius", csv("ior=1.3", "2,0.05,0.001\n1,0.1,0.001\n3,0.02,0.001\n"), fit,
       "not above the previous row"},
      {"two_inputs_two_indices",
       [](const fs::path& dir) {
         csv("ior=1.3", rows_of(0.1), "a.csv")(dir);
         csv("ior=1.5", rows_of(0.1), "b.csv")(dir);
       },
       "fit {dir}/a.csv {dir}/b.csv -o {dir}/m.json", "b.csv: relative index 1.5"},
      {"values_at_the_edge_of_nothing", csv("ior=1.3", rows_of(1e-300)), fit, "m.json"},
      {"one_image_at_two_exposures",
       capture_edited([](Json& c) { c["images"][1]["path"] = c["images"][0]["path"]; }), acq,
       "is already image 0"},
      {"white_reference_fifty_times_darker",
       capture_edited([](Json& c) {
         for (auto& image : c["white_reference"]["images"])
           image["exposure_s"] = image["exposure_s"].get<double>() * 50;
       }),
       acq, "field 'white_reference': the sample returns"},
      {"simulate_exposure_acquire_refuses", nullptr,
       "simulate --material marble --photons 1000 --size 16 -o {dir}/s --exposures 1e-12,1/60",
       "--exposures"},
      {"capture_ior_ten", capture_edited([](Json& c) { c["ior"] = 10; }), acq, "field 'ior'"},
      {"capture_thickness_negative", capture_edited([](Json& c) { c["thickness_mm"] = -1; }), acq,
       "field 'thickness_mm'"},
      {"capture_far_side_without_thickness",
       capture_edited([](Json& c) { c["side"] = "transmitted"; }), acq, "field 'side'"},
      {"capture_side_misspelt",
       capture_edited([](Json& c) {
         c["thickness_mm"] = 2;
         c["side"] = "transmited";
       }),
       acq, "field 'side'"},
      {"white_reflectance_above_one",
       capture_edited([](Json& c) { c["white_reference"]["reflectance"] = 1.5; }), acq,
       "white_reference.reflectance"},
      {"csv_thickness_zero", csv("ior=1.3 thickness_mm=0", rows_of(0.1)), fit, "thickness_mm"},
      {"csv_ior_negative", csv("ior=-1.3", rows_of(0.1)), fit, "p.csv"},
      {"simulate_exposure_huge", nullptr,
       "simulate --material marble --photons 1000 --size 16 -o {dir}/s --exposures 1/60,1e7",
       "--exposures"},
  };
}

class Physics : public ::testing::TestWithParam<BadCase> {};
TEST_P(Physics, ImpossibleOrContradictoryInputsAreRefused) { expect_clean_refusal(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Table, Physics, ::testing::ValuesIn(physics_cases()),
                         [](const auto& info) { return info.param.name; });

// ---- injection: names are data --------------------------------------------------------------------

// Each export of a material whose name holds what would break the target's syntax (an XML comment's
// "--", a pbrt string's closing quote escaped by a trailing backslash, control characters, markup):
// the file stays well formed (every XML comment without "--" or a trailing "-", no raw control
// character; pbrt's quotes pair, none escaped), and what lucent prints has no raw control character.
struct NamedExport {
  std::string label, name, target;
};
void PrintTo(const NamedExport& c, std::ostream* os) { *os << c.label; }

std::vector<NamedExport> named_exports() {
  const std::vector<std::pair<std::string, std::string>> names = {
      {"dashes", "a--b-"}, {"backslash", "end\\"}, {"escape_newline", "x\x1b[31m\ny"},
      {"markup", "q\"uote<&>'"}};
  std::vector<NamedExport> out;
  for (const auto& [label, name] : names)
    for (const char* target : {"mitsuba", "materialx", "openpbr", "pbrt", "gltf"})
      out.push_back({label + "_" + target, name, target});
  return out;
}

class Injection : public ::testing::TestWithParam<NamedExport> {};
TEST_P(Injection, NamesAreDataInEveryExport) {
  const NamedExport& c = GetParam();
  const fs::path dir = scratch_dir("hostile-names-" + c.label);
  nlohmann::json m = nlohmann::json::parse(
      read_bytes(fs::path(LUCENT_SOURCE_DIR) / "materials/library/marble.json"));
  m["name"] = c.name;
  write_file(dir / "m.json", m.dump());
  const std::string ext = c.target == "pbrt"      ? ".pbrt"
                          : c.target == "mitsuba" ? ".xml"
                          : c.target == "gltf"    ? ".gltf"
                                                  : ".mtlx";
  const fs::path out = dir / ("out" + ext);
  const CommandResult r = run_lucent("export --material \"" + (dir / "m.json").string() + "\" --to " +
                                     c.target + " -o \"" + out.string() + "\"");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char ch : r.out + r.err)
    EXPECT_FALSE(static_cast<unsigned char>(ch) < 0x20 && ch != '\n') << "raw control character";
  const std::string text = read_bytes(out);
  if (ext == ".pbrt") {
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
      if (!line.empty() && line[0] == '#') continue;
      EXPECT_EQ(std::count(line.begin(), line.end(), '"') % 2, 0) << line;
      EXPECT_EQ(line.find('\\'), std::string::npos) << line;
    }
  } else if (ext == ".gltf") {
    EXPECT_TRUE(nlohmann::json::accept(text)) << text.substr(0, 300);
  } else {
    for (std::size_t at = text.find("<!--"); at != std::string::npos; at = text.find("<!--", at + 4)) {
      const std::size_t end = text.find("-->", at + 4);
      ASSERT_NE(end, std::string::npos);
      const std::string body = text.substr(at + 4, end - at - 4);
      EXPECT_EQ(body.find("--"), std::string::npos) << body;
      EXPECT_NE(body.back(), '-') << body;
    }
  }
  for (const char ch : text)
    EXPECT_FALSE(static_cast<unsigned char>(ch) < 0x20 && ch != '\n' && ch != '\t' && ch != '\r');
  fs::remove_all(dir);
}
INSTANTIATE_TEST_SUITE_P(Table, Injection, ::testing::ValuesIn(named_exports()),
                         [](const auto& info) { return info.param.label; });

// An error naming a file whose name holds a newline and an escape stays one line, escapes shown.
TEST(InjectionErrors, AnErrorNamingAHostileFileNameIsOneLine) {
  const fs::path dir = scratch_dir("hostile-error-name");
  const std::string name = (dir / "bad\nname\x1b[2J.json").string();
  const CommandResult r = run_lucent("fit \"" + name + "\" --ior 1.3 -o \"" + (dir / "m.json").string() + "\"");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("\\x0a"), std::string::npos) << r.err;
  fs::remove_all(dir);
}

// A name that is not UTF-8 (nlohmann refuses to write it into JSON) is one clean error, not an
// internal one, and nothing is written.
TEST(InjectionErrors, ANameThatIsNotUtf8IsOneCleanError) {
  const fs::path dir = scratch_dir("hostile-utf8");
  const CommandResult r = run_lucent("fit \"" + (world() / "acq/profile.json").string() +
                                     "\" --quality fast -q --name \"$(printf 'bad\\377\\376name')\" -o \"" +
                                     (dir / "m.json").string() + "\"");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("not valid UTF-8"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "m.json"));
  fs::remove_all(dir);
}

// ---- smaller -------------------------------------------------------------------------------------

// A FIFO and a Unix socket in the case's folder (a socket is made by binding one; it stays after
// the descriptor closes).
void make_fifo(const fs::path& p) {
  ::mkfifo(p.c_str(), 0644);
}
void make_socket(const fs::path& p) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un a{};
  a.sun_family = AF_UNIX;
  std::snprintf(a.sun_path, sizeof a.sun_path, "%s", p.c_str());
  ::bind(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a);
  ::close(fd);
}

// Outputs that are not files (renaming over a device replaced /dev/full and the /dev/stdout link
// with regular files when run as root), names the file system refuses, inputs that are folders or
// devices, meshes without area: each one line naming the culprit, nothing written or replaced.
std::vector<BadCase> smaller_cases() {
  const std::string profile = "profile --material marble --r 1 -o ";
  const std::string fit = "fit {world}/acq/profile.json --quality fast -q -o ";
  const std::string render =
      "render --material marble --technique reference --size 8x8 --reference-samples-pixel 1 ";
  const auto fifo = [](std::string name) {
    return [=](const fs::path& d) { make_fifo(d / name); };
  };
  return {
      {"output_a_fifo", fifo("p.csv"), profile + "{dir}/p.csv", "a FIFO"},
      {"output_a_socket", [](const fs::path& d) { make_socket(d / "p.csv"); },
       profile + "{dir}/p.csv", "a socket"},
      {"output_a_link_to_a_fifo",
       [](const fs::path& d) { make_fifo(d / "f"), fs::create_symlink(d / "f", d / "p.csv"); },
       profile + "{dir}/p.csv", "a FIFO"},
      {"output_dev_full", nullptr, profile + "/dev/full", "/dev"},
      {"output_proc_fd", nullptr, profile + "/proc/self/fd/1", "/proc"},
      {"material_output_a_fifo", fifo("m.json"), fit + "{dir}/m.json", "a FIFO"},
      {"render_output_a_fifo", fifo("r.png"), render + "--mesh {world}/cube.obj -o {dir}/r.png",
       "a FIFO"},
      {"export_output_a_fifo", fifo("m.pbrt"), "export --material marble --to pbrt -o {dir}/m.pbrt",
       "a FIFO"},
      {"acquire_output_in_dev", nullptr, "acquire {world}/cap/capture.json -o /dev/lucent-acquire",
       "/dev"},
      {"output_name_too_long", nullptr, fit + "{dir}/" + std::string(260, 'n') + ".json",
       "File name too long"},
      {"output_folder_name_too_long", nullptr, fit + "{dir}/" + std::string(300, 'd') + "/m.json",
       "m.json"},
      {"input_a_folder", [](const fs::path& d) { fs::create_directories(d / "p.csv"); },
       "fit {dir}/p.csv -o {dir}/m.json", "p.csv"},
      {"input_dev_zero", nullptr, "fit /dev/zero -o {dir}/m.json", "/dev/zero"},
      {"mesh_dev_zero", nullptr, render + "--mesh /dev/zero -o {dir}/r.png", "/dev/zero"},
      {"mesh_zero_area",
       bytes_file("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nf 1 2 3\nf 2 3 4\n"),
       render + "--mesh {dir}/flat.obj -o {dir}/r.exr", "zero area"},
      {"mesh_repeated_indices", bytes_file("d.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 1 2\n"),
       render + "--mesh {dir}/d.obj -o {dir}/r.exr", "d.obj"},
      {"compare_a_folder", [](const fs::path& d) { fs::create_directories(d / "a.exr"); },
       "compare {dir}/a.exr {dir}/a.exr", "a.exr"},
  };
}

class Smaller : public ::testing::TestWithParam<BadCase> {};
TEST_P(Smaller, AreRefusedCleanly) {
  expect_clean_refusal(GetParam());
}
INSTANTIATE_TEST_SUITE_P(Table, Smaller, ::testing::ValuesIn(smaller_cases()),
                         [](const auto& info) { return info.param.name; });

// A UTF-8 byte order mark (spreadsheets write one) is not part of the first column's name: a
// profile CSV and a manifest that start with one are read as without it (the profile is the
// standard dipole's, fitted with it).
TEST(SmallerAccepted, AByteOrderMarkIsNotAColumn) {
  const fs::path dir = scratch_dir("hostile-bom");
  write_file(dir / "p.csv", "\xEF\xBB\xBF" + read_bytes(world() / "radial.csv"));
  write_file(dir / "m.csv", "\xEF\xBB\xBFinput,output,ior,model\n" + (dir / "p.csv").string() +
                                ",o.json,1.5,dipole\n");
  const CommandResult one = run_lucent("fit \"" + (dir / "p.csv").string() +
                                       "\" --ior 1.5 --model dipole --quality fast -q -o \"" +
                                       (dir / "a.json").string() + "\"");
  EXPECT_EQ(one.exit_code, 0) << one.err;
  const CommandResult batch =
      run_lucent("fit --batch \"" + (dir / "m.csv").string() + "\" --quality fast -q -o \"" +
                 (dir / "s.json").string() + "\"");
  EXPECT_EQ(batch.exit_code, 0) << batch.err;
  EXPECT_TRUE(fs::exists(dir / "a.json"));
  EXPECT_TRUE(fs::exists(dir / "o.json"));
  fs::remove_all(dir);
}

// TMPDIR naming a folder that is not there: bench says so in one line (it was an internal error).
TEST(SmallerAccepted, BenchWithoutItsTmpdirSaysSo) {
  const fs::path dir = scratch_dir("hostile-tmpdir");
  const std::string command = "TMPDIR=\"" + (dir / "gone").string() + "\" \"" + LUCENT_BINARY +
                              "\" bench fit --out-dir \"" + dir.string() + "\" >/dev/null 2>\"" +
                              (dir / "err").string() + "\"";
  const int status = std::system(command.c_str());
  const std::string err = read_text(dir / "err");
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << status << " " << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_NE(err.find("TMPDIR"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir / "fit_tradeoff.csv"));
  fs::remove_all(dir);
}

// A legal output name of 250 bytes is written (its temporary's name, which adds a dot and a
// suffix, was over the 255-byte limit and the output refused).
TEST(SmallerAccepted, ALongLegalOutputNameIsWritten) {
  const fs::path dir = scratch_dir("hostile-smaller");
  const fs::path out = dir / (std::string(245, 'n') + ".json");
  const CommandResult r =
      run_lucent("fit \"" + (world() / "acq/profile.json").string() + "\" --quality fast -q -o \"" +
                 out.string() + "\"");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(out));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace lucent::testing
