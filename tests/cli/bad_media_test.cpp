// Bad-input tables for lucent's images and meshes: exposure brackets (PNG), OpenEXR and Radiance
// images (captures, comparisons, environment maps) and PLY/OBJ meshes. See bad_input.h.

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include <cstring>

#include "bad_input.h"
#include "lucent/imaging/image_io.h"
#include "raw_exr.h"

namespace lucent::testing {
namespace {

// ---- helpers ------------------------------------------------------------------------------------

// An EXR with any values, NaN included (lucent's own writer refuses non-finite pixels).
void write_exr_with(const fs::path& path, int w, int h, float value, float special = 0,
                    bool with_special = false) {
  imaging::ImageRgb image(w, h, value);
  if (with_special) image.data[3 * (std::size_t(w) * h / 2)] = special;
  lucent::testing::write_raw_exr(path, image);
}

std::function<void(const fs::path&)> exr_file(std::string name, float value, float special = 0,
                                              bool with_special = false) {
  return [=](const fs::path& d) { write_exr_with(d / name, 16, 8, value, special, with_special); };
}

void write_png_of(const fs::path& path, int w, int h, int max, std::uint16_t value) {
  imaging::RawImage image(w, h, max);
  for (auto& v : image.data) v = value;
  imaging::write_png(path, image);
}

std::uint32_t crc32(const std::string& bytes) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (unsigned char b : bytes) {
    crc ^= b;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

std::string be32(std::uint32_t v) {
  return {char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
}

// A PNG whose header claims 100000 x 100000 pixels and has no image data.
// A PNG whose header claims w x h pixels and holds none (refused by its header, before decoding).
std::string png_claiming(std::uint32_t w, std::uint32_t h) {
  const std::string ihdr = "IHDR" + be32(w) + be32(h) + std::string("\x08\x02\0\0\0", 5);
  return std::string("\x89PNG\r\n\x1a\n", 8) + be32(13) + ihdr + be32(crc32(ihdr)) + be32(0) +
         "IEND" + be32(crc32("IEND"));
}

// A small real EXR whose dataWindow is patched to claim 16384 x 16384 pixels.
void write_forged_exr(const fs::path& path) {
  {
    Imf::Header header(4, 4);
    header.channels().insert("R", Imf::Channel(Imf::FLOAT));
    header.channels().insert("G", Imf::Channel(Imf::FLOAT));
    header.channels().insert("B", Imf::Channel(Imf::FLOAT));
    std::vector<float> v(48, 1.0f);
    Imf::OutputFile file(path.c_str(), header);
    Imf::FrameBuffer frame;
    for (int c = 0; c < 3; ++c)
      frame.insert(std::string(1, "RGB"[c]),
                   Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(v.data() + c), 12, 48));
    file.setFrameBuffer(frame);
    file.writePixels(4);
  }
  std::string b = read_bytes(path);
  const std::string key = std::string("dataWindow\0box2i\0", 17);
  const std::size_t at = b.find(key);
  if (at == std::string::npos) return;
  const std::int32_t box[4] = {0, 0, 16383, 16383};
  std::memcpy(b.data() + at + key.size() + 4, box, sizeof box);
  write_file(path, b);
}

std::string png_bomb() {
  const std::string ihdr = "IHDR" + be32(100000) + be32(100000) + std::string("\x08\x02\0\0\0", 5);
  return std::string("\x89PNG\r\n\x1a\n", 8) + be32(13) + ihdr + be32(crc32(ihdr)) + be32(0) +
         "IEND" + be32(crc32("IEND"));
}

// The world's capture with one image (or the dark frame, or a white image) replaced by `file` in
// the case folder, which `make` writes.
std::function<void(const fs::path&)> capture_with(std::string which,
                                                  std::function<void(const fs::path&)> make) {
  return [=](const fs::path& d) {
    make(d / "img.png");
    Json c = read_json(world() / "capture_abs.json");
    const std::string path = (d / "img.png").string();
    if (which == "dark")
      c["dark"] = path;
    else if (which == "white")
      c["white_reference"]["images"][1]["path"] = path;
    else if (which == "all") {
      for (auto& image : c["images"]) image["path"] = path;
      c.erase("dark");
      c.erase("white_reference");
      c["images"] = Json::array({c["images"][0]});
    } else
      c["images"][2]["path"] = path;
    write_file(d / "c.json", c.dump(2));
  };
}

std::function<void(const fs::path&)> bytes_at(std::string bytes) {
  return [=](const fs::path& p) { write_file(p, bytes); };
}

// The world's capture as one HDR image (no brackets), the image made by `make` in the case folder.
std::function<void(const fs::path&)> capture_hdr(std::function<void(const fs::path&)> make) {
  return [=](const fs::path& d) {
    if (make) make(d / "h.exr");
    Json c = read_json(world() / "capture_abs.json");
    c.erase("images");
    c.erase("dark");
    c.erase("white_reference");
    c["hdr"] = (d / "h.exr").string();
    write_file(d / "c.json", c.dump(2));
  };
}

// An EXR whose only channel is Z: neither RGB nor Y.
void write_z_only_exr(const fs::path& path) {
  Imf::Header header(4, 4);
  header.channels().insert("Z", Imf::Channel(Imf::FLOAT));
  std::vector<float> z(16, 1.0f);
  Imf::OutputFile file(path.c_str(), header);
  Imf::FrameBuffer frame;
  frame.insert("Z", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(z.data()), 4, 16));
  file.setFrameBuffer(frame);
  file.writePixels(4);
}

// ---- brackets (PNG through lucent acquire) ------------------------------------------------------
std::vector<BadCase> bracket_cases() {
  const std::string args = "acquire {dir}/c.json -o {dir}/out";
  const auto bracket = [](const std::string& part, int keep) {
    return [=](const fs::path& p) {
      const std::string b = read_bytes(world() / "cap/bracket_2.png");
      write_file(p, keep > 0 ? b.substr(0, std::size_t(keep)) : b.substr(0, b.size() / 2) + part);
    };
  };
  return {
      {"bracket_text", capture_with("image", bytes_at("not an image\n")), args, "img.png"},
      {"bracket_empty", capture_with("image", bytes_at("")), args, "img.png"},
      {"bracket_truncated", capture_with("image", bracket("", 0)), args, "img.png"},
      {"bracket_header_only", capture_with("image", bracket("", 40)), args, "img.png"},
      {"bracket_png_bomb", capture_with("image", bytes_at(png_bomb())), args, "img.png"},
      {"bracket_other_size",
       capture_with("image", [](const fs::path& p) { write_png_of(p, 8, 8, 65535, 100); }), args,
       "img.png"},
      {"bracket_8_bit_among_16",
       capture_with("image",
                    [](const fs::path& p) {
                      const int n = 128;  // the bundled capture's size
                      write_png_of(p, n, n, 255, 10);
                    }),
       args, "img.png"},
      {"bracket_directory",
       capture_with("image", [](const fs::path& p) { fs::create_directory(p); }), args, "img.png"},
      {"bracket_all_black",
       capture_with("all", [](const fs::path& p) { write_png_of(p, 64, 64, 65535, 0); }), args,
       "all-black"},
      {"bracket_all_saturated",
       capture_with("all", [](const fs::path& p) { write_png_of(p, 64, 64, 65535, 65535); }), args,
       "all-saturated"},
      {"dark_text", capture_with("dark", bytes_at("dark\n")), args, "img.png"},
      {"dark_other_size",
       capture_with("dark", [](const fs::path& p) { write_png_of(p, 8, 8, 65535, 0); }), args,
       "img.png"},
      {"white_text", capture_with("white", bytes_at("white\n")), args, "img.png"},
      {"white_other_size",
       capture_with("white", [](const fs::path& p) { write_png_of(p, 8, 8, 65535, 100); }), args,
       "img.png"},
      {"bracket_jpeg_bytes_as_png", capture_with("image", bytes_at("\xff\xd8\xff\xe0garbage")),
       args, "img.png"},
      {"capture_hdr_text", capture_hdr(bytes_at("not an exr")), args, "h.exr"},
      // A fuzz finding (fuzz_image_headers): bytes OpenCV sniffed as DICOM, whose reader aborted.
      {"bracket_fuzzed_dicom_abort",
       capture_with("image",
                    [](const fs::path& p) {
                      fs::copy_file(fs::path(LUCENT_SOURCE_DIR) / "tests/cli/data/fuzz_image_gdcm_abort.png", p);
                    }),
       args, "img.png"},
      {"bracket_png_header_20000", capture_with("image", bytes_at(png_claiming(20000, 20000))),
       args, "20000 x 20000"},
      {"bracket_png_header_wide", capture_with("image", bytes_at(png_claiming(40000, 2))), args,
       "img.png"},
      {"capture_hdr_header_claims_16384_squared", capture_hdr(write_forged_exr), args,
       "h.exr"},
  };
}

// ---- OpenEXR and Radiance images (compare, --env, capture hdr) ----------------------------------
std::vector<BadCase> image_cases() {
  const std::string cmp = "compare {dir}/a.exr {world}/env.exr --json";
  const std::string env =
      "render --material marble --mesh sphere --technique reference --size 8x8 "
      "--reference-samples-pixel 1 -o {dir}/out.exr --env ";
  return {
      {"exr_missing", nullptr, cmp, "a.exr"},
      {"exr_text", bytes_file("a.exr", "hello"), cmp, "a.exr"},
      {"exr_empty", bytes_file("a.exr", ""), cmp, "a.exr"},
      {"exr_truncated",
       [](const fs::path& d) {
         const std::string b = read_bytes(world() / "env.exr");
         write_file(d / "a.exr", b.substr(0, b.size() / 2));
       },
       cmp, "a.exr"},
      {"exr_directory", [](const fs::path& d) { fs::create_directory(d / "a.exr"); }, cmp, "a.exr"},
      {"exr_size_mismatch", [](const fs::path& d) { write_exr_with(d / "a.exr", 8, 8, 0.5f); }, cmp,
       "size"},
      {"env_nan", exr_file("e.exr", 0.5f, std::nanf(""), true), env + "{dir}/e.exr", "e.exr"},
      {"env_inf", exr_file("e.exr", 0.5f, INFINITY, true), env + "{dir}/e.exr", "e.exr"},
      {"env_1e38", exr_file("e.exr", 1e38f), env + "{dir}/e.exr", "e.exr"},
      {"env_black", exr_file("e.exr", 0.0f), env + "{dir}/e.exr", "black"},
      {"env_wrong_extension", bytes_file("e.png", "x"), env + "{dir}/e.png", "e.png"},
      {"env_missing", nullptr, env + "{dir}/none.exr", "none.exr"},
      {"env_light_count_zero", nullptr, env + "{world}/env.exr:0", "--env"},
      {"env_hdr_text", bytes_file("e.hdr", "#?RADIANCE\nnothing\n"), env + "{dir}/e.hdr", "e.hdr"},
      {"env_hdr_truncated",
       [](const fs::path& d) {
         const std::string b = read_bytes(world() / "env.hdr");
         write_file(d / "e.hdr", b.substr(0, b.size() - 100));
       },
       env + "{dir}/e.hdr", "e.hdr"},
      {"env_overwritten_by_output",
       [](const fs::path& d) { fs::copy_file(world() / "env.exr", d / "e.exr"); },
       "render --material marble --mesh sphere --technique reference --size 8x8 "
       "--reference-samples-pixel 1 --env {dir}/e.exr -o {dir}/e.exr",
       "is an input"},
      {"exr_reference_missing",
       [](const fs::path& d) { fs::copy_file(world() / "env.exr", d / "a.exr"); },
       "compare {dir}/a.exr {dir}/none.exr", "none.exr"},
      {"exr_reference_text", bytes_file("r.exr", "text"), "compare {world}/env.exr {dir}/r.exr",
       "r.exr"},
      {"exr_no_rgb_channels", [](const fs::path& d) { write_z_only_exr(d / "a.exr"); }, cmp,
       "neither R, G, B nor Y"},
      {"exr_dev_zero", nullptr, "compare /dev/zero {world}/env.exr", "/dev/zero"},
      {"exr_hdr_given_to_compare",
       [](const fs::path& d) { fs::copy_file(world() / "env.hdr", d / "a.exr"); }, cmp, "a.exr"},
      {"capture_hdr_missing", capture_hdr(nullptr), "acquire {dir}/c.json -o {dir}/out", "h.exr"},
      {"capture_hdr_all_nan", capture_hdr([](const fs::path& p) {
         write_raw_exr(p, imaging::ImageRgb(32, 32, std::nanf("")));
       }),
       "acquire {dir}/c.json -o {dir}/out", "no finite pixels"},
      {"capture_hdr_truncated", capture_hdr([](const fs::path& p) {
         const std::string b = read_bytes(world() / "env.exr");
         write_file(p, b.substr(0, b.size() - 20));
       }),
       "acquire {dir}/c.json -o {dir}/out", "h.exr"},
      {"env_light_count_huge", nullptr, env + "{world}/env.exr:5000", "--env"},
      {"env_directory", [](const fs::path& d) { fs::create_directory(d / "e.exr"); },
       env + "{dir}/e.exr", "e.exr"},
      {"env_dev_zero", nullptr, env + "/dev/zero", "/dev/zero"},
      {"env_hdr_header_only",
       bytes_file("e.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8 +X 16\n"),
       env + "{dir}/e.hdr", "e.hdr"},
      {"env_exr_text", bytes_file("e.exr", "not an exr"), env + "{dir}/e.exr", "e.exr"},
      {"compare_difference_overwrites_input",
       [](const fs::path& d) { fs::copy_file(world() / "env.exr", d / "a.exr"); },
       "compare {dir}/a.exr {world}/env.exr --difference {dir}/a.exr", "is an input"},
  };
}

// ---- PLY / OBJ meshes (render --mesh) -----------------------------------------------------------
std::vector<BadCase> mesh_cases() {
  const std::string pre =
      "render --material marble --technique reference --size 8x8 "
      "--reference-samples-pixel 1 -o {dir}/out.exr --mesh ";
  const auto from_world = [](std::string seed, std::string name,
                             std::function<std::string(std::string)> edit) {
    return [=](const fs::path& d) { write_file(d / name, edit(read_bytes(world() / seed))); };
  };
  const auto sub = [](std::string from, std::string to) {
    return [=](std::string s) { return replace_all(s, from, to); };
  };
  return {
      {"ply_binary_one_byte_short",
       from_world("cube_binary.ply", "m.ply",
                  [](std::string s) { return s.substr(0, s.size() - 1); }),
       pre + "{dir}/m.ply", "m.ply"},
      {"ply_huge_vertex_count",
       from_world("cube_binary.ply", "m.ply", sub("element vertex 8", "element vertex 2000000000")),
       pre + "{dir}/m.ply", "m.ply"},
      {"ply_nan_vertex", from_world("cube_ascii.ply", "m.ply", sub("\n0 0 0\n", "\nnan 0 0\n")),
       pre + "{dir}/m.ply", "not finite"},
      {"ply_index_out_of_range",
       from_world("cube_ascii.ply", "m.ply", sub("4 0 1 3 2", "4 0 1 3 99")), pre + "{dir}/m.ply",
       "out of range"},
      {"ply_not_ply", bytes_file("m.ply", "solid x\n"), pre + "{dir}/m.ply", "not a PLY"},
      {"ply_empty", bytes_file("m.ply", ""), pre + "{dir}/m.ply", "m.ply"},
      {"ply_no_end_header", from_world("cube_ascii.ply", "m.ply", sub("end_header", "end_headers")),
       pre + "{dir}/m.ply", "m.ply"},
      {"ply_no_faces",
       from_world("cube_ascii.ply", "m.ply",
                  [](std::string s) { return s.substr(0, s.find("4 0 1 3 2")); }),
       pre + "{dir}/m.ply", "m.ply"},
      {"obj_nan", from_world("cube.obj", "m.obj", sub("v 0 0 0", "v nan 0 0")), pre + "{dir}/m.obj",
       "not finite"},
      {"obj_index_zero", from_world("cube.obj", "m.obj", sub("f 1/1/1", "f 0/1/1")),
       pre + "{dir}/m.obj", "vertex index"},
      {"obj_out_of_range", from_world("cube.obj", "m.obj", sub("f 1/1/1", "f 50/1/1")),
       pre + "{dir}/m.obj", "out of range"},
      {"obj_no_faces", bytes_file("m.obj", "v 0 0 0\nv 1 0 0\n"), pre + "{dir}/m.obj",
       "no triangles"},
      {"mesh_missing", nullptr, pre + "{dir}/none.ply", "none.ply"},
      {"mesh_directory", [](const fs::path& d) { fs::create_directory(d / "m.ply"); },
       pre + "{dir}/m.ply", "m.ply"},
      {"mesh_stl", bytes_file("m.stl", "solid x\n"), pre + "{dir}/m.stl", "unsupported"},
      {"mesh_coincident_vertices", bytes_file("m.obj", "v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n"),
       pre + "{dir}/m.obj", "coincide"},
      {"mesh_dragon_5", nullptr, pre + "dragon:5", "dragon:5"},
  };
}

std::vector<BadCase> all_media_cases() {
  std::vector<BadCase> all;
  for (auto table : {bracket_cases(), image_cases(), mesh_cases()})
    all.insert(all.end(), table.begin(), table.end());
  return all;
}

class BadMedia : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadMedia, AreRefusedCleanly) {
  expect_clean_refusal(GetParam());
}

INSTANTIATE_TEST_SUITE_P(Table, BadMedia, ::testing::ValuesIn(all_media_cases()),
                         [](const auto& info) { return info.param.name; });

}  // namespace
}  // namespace lucent::testing
