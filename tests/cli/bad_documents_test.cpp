// Bad-input tables for lucent's documents: material JSON, capture JSON, profile JSON, profile CSV
// and the BSSRDF configuration CSV. See bad_input.h for what every case asserts.
#include "bad_input.h"

namespace lucent::testing {
namespace {

// What any JSON reader must refuse, whatever the document: `file` in the case folder, read by
// `args`.
std::vector<BadCase> json_level_cases(const std::string& prefix, const std::string& file,
                                      const std::string& args, const std::string& base) {
  const std::string path = "{dir}/" + file;
  return {
      {prefix + "_missing", nullptr, args, file + ": cannot open"},
      {prefix + "_directory", [file](const fs::path& d) { fs::create_directory(d / file); }, args,
       "cannot open"},
      {prefix + "_empty", bytes_file(file, ""), args, "not valid JSON"},
      {prefix + "_not_json", bytes_file(file, "format = lucent\n"), args, "not valid JSON"},
      {prefix + "_truncated",
       [base, file](const fs::path& d) {
         const std::string text = read_bytes(world() / base);
         write_file(d / file, text.substr(0, text.size() / 2));
       },
       args, "not valid JSON"},
      {prefix + "_top_level_array", bytes_file(file, "[1, 2, 3]"), args, file},
      {prefix + "_duplicate_key",
       [base, file](const fs::path& d) {
         std::string text = read_bytes(world() / base);
         text.insert(text.find('{') + 1, "\"format\": \"x\",");
         write_file(d / file, text);
       },
       args, "duplicate key \"format\""},
      {prefix + "_number_overflow",
       [base, file](const fs::path& d) {
         std::string text = read_bytes(world() / base);
         text.insert(text.find('{') + 1, "\"x\": 1e309,");
         write_file(d / file, text);
       },
       args, "number overflow"},
      {prefix + "_nan_token",
       [base, file](const fs::path& d) {
         std::string text = read_bytes(world() / base);
         text.insert(text.find('{') + 1, "\"x\": NaN,");
         write_file(d / file, text);
       },
       args, "not valid JSON"},
      {prefix + "_binary_garbage", bytes_file(file, std::string("\x89PNG\r\n\x1a\n\0\0", 10)),
       args, "not valid JSON"},
  };
}

// The provenance bomb of the issue: 100,000 nested levels inside an otherwise valid document.
BadCase deep_case(const std::string& prefix, const std::string& file, const std::string& args,
                  const std::string& base) {
  return {prefix + "_deep_provenance",
          [base, file](const fs::path& d) {
            std::string text = read_bytes(world() / base);
            text.insert(text.find('{') + 1, "\"deep\": " + deep_nesting(100000) + ",");
            write_file(d / file, text);
          },
          args, "nested deeper than 128"};
}

std::vector<BadCase> with_json_level(std::vector<BadCase> own, const std::string& prefix,
                                     const std::string& file, const std::string& args,
                                     const std::string& base) {
  std::vector<BadCase> all = json_level_cases(prefix, file, args, base);
  all.push_back(deep_case(prefix, file, args, base));
  all.insert(all.end(), own.begin(), own.end());
  return all;
}

// ---- material JSON (lucent profile --material FILE) --------------------------------------------
std::vector<BadCase> material_cases() {
  const std::string base = "marble.json";
  const std::string args = "profile --material {dir}/m.json --r 1 -o {dir}/out.csv";
  const auto edit = [&](std::function<void(Json&)> f) { return edited_json(base, "m.json", f); };
  return with_json_level(
      {
          {"material_sigma_a_huge", edit([](Json& j) { j["sigma_a"][0] = 1e308; }), args,
           "field 'sigma_a'"},
          {"material_sigma_a_negative", edit([](Json& j) { j["sigma_a"][1] = -0.1; }), args,
           "field 'sigma_a'"},
          {"material_sigma_a_two", edit([](Json& j) { j["sigma_a"] = {0.1, 0.2}; }), args,
           "field 'sigma_a'"},
          {"material_ior_tiny", edit([](Json& j) { j["ior"] = 1e-300; }), args, "field 'ior'"},
          {"material_ior_string", edit([](Json& j) { j["ior"] = "1.5"; }), args, "field 'ior'"},
          {"material_model_foo", edit([](Json& j) { j["model"] = "foo"; }), args,
           "field 'model'"},
          {"material_unknown_field", edit([](Json& j) { j["sigma_t"] = {1, 1, 1}; }), args,
           "unknown field"},
          {"material_no_format", edit([](Json& j) { j.erase("format"); }), args,
           "field 'format'"},
          {"material_newer_version", edit([](Json& j) { j["version"] = 99; }), args,
           "field 'version'"},
          {"material_empty_name", edit([](Json& j) { j["name"] = ""; }), args, "field 'name'"},
          {"material_dev_zero", nullptr, "profile --material /dev/zero --r 1 -o {dir}/out.csv",
           "/dev/zero: larger than"},
      },
      "material", "m.json", args, base);
}

// ---- capture JSON (lucent acquire FILE -o OUT) -------------------------------------------------
std::vector<BadCase> capture_cases() {
  const std::string base = "capture_abs.json";
  const std::string args = "acquire {dir}/c.json -o {dir}/out";
  const auto edit = [&](std::function<void(Json&)> f) { return edited_json(base, "c.json", f); };
  return with_json_level(
      {
          {"capture_beam_power_subnormal", edit([](Json& j) { j["beam_power"] = 1e-320; }), args,
           "field 'beam_power'"},
          {"capture_pixel_pitch_huge", edit([](Json& j) { j["pixel_pitch_mm"] = 1e300; }), args,
           "pixel_pitch_mm"},
          {"capture_pixel_pitch_zero", edit([](Json& j) { j["pixel_pitch_mm"] = 0; }), args,
           "pixel_pitch_mm"},
          {"capture_exposure_zero", edit([](Json& j) { j["images"][0]["exposure_s"] = 0; }), args,
           "exposure_s"},
          {"capture_exposures_not_increasing",
           edit([](Json& j) { j["images"][1]["exposure_s"] = 0.0001; }), args, "increase"},
          {"capture_image_missing",
           edit([](Json& j) { j["images"][2]["path"] = "/nonexistent/b.png"; }), args,
           "/nonexistent/b.png"},
          {"capture_polar_95", edit([](Json& j) { j["incidence"]["polar_deg"] = 95; }), args,
           "polar_deg"},
          {"capture_ior_zero", edit([](Json& j) { j["ior"] = 0; }), args, "field 'ior'"},
          {"capture_response_foo", edit([](Json& j) { j["response"] = "foo"; }), args,
           "response"},
          {"capture_white_reflectance_2",
           edit([](Json& j) { j["white_reference"]["reflectance"] = 2; }), args, "reflectance"},
          {"capture_beam_point_one", edit([](Json& j) { j["beam_point_px"] = {3}; }), args,
           "beam_point_px"},
          {"capture_unknown_field", edit([](Json& j) { j["exposure"] = 1; }), args, "exposure"},
          {"capture_wrong_format", edit([](Json& j) { j["format"] = "lucent-material"; }), args,
           "format"},
          {"capture_output_holds_input",
           [base](const fs::path& d) {
             fs::create_directory(d / "cap");
             write_file(d / "cap/capture.json", read_bytes(world() / base));
           },
           "acquire {dir}/cap/capture.json -o {dir}/cap", "holds"},
      },
      "capture", "c.json", args, base);
}

// ---- profile JSON (lucent fit FILE -o OUT) -----------------------------------------------------
std::vector<BadCase> profile_json_cases() {
  const std::string base = "acq/profile.json";
  const std::string args = "fit {dir}/p.json -o {dir}/m.json";
  const auto edit = [&](std::function<void(Json&)> f) { return edited_json(base, "p.json", f); };
  return with_json_level(
      {
          {"profile_wrong_format", edit([](Json& j) { j["format"] = "lucent-capture"; }), args,
           "format"},
          {"profile_newer_version", edit([](Json& j) { j["version"] = 7; }), args, "version"},
          {"profile_no_radial", edit([](Json& j) { j.erase("radial"); }), args, "radial"},
          {"profile_r_string", edit([](Json& j) { j["radial"]["r_mm"][3] = "x"; }), args,
           "radial.r_mm"},
          {"profile_short_values", edit([](Json& j) { j["radial"]["value"][1].erase(0); }), args,
           "radial.value"},
          {"profile_pitch_huge", edit([](Json& j) { j["pixel_pitch_mm"] = 1e300; }), args,
           "pixel_pitch_mm"},
          {"profile_ior_zero", edit([](Json& j) { j["ior"] = 0; }), args, "field 'ior'"},
          {"profile_overwrites_input", [base](const fs::path& d) {
             write_file(d / "p.json", read_bytes(world() / base));
           },
           "fit {dir}/p.json -o {dir}/p.json", "is an input of this run"},
          {"profile_output_folder_missing", [base](const fs::path& d) {
             write_file(d / "p.json", read_bytes(world() / base));
           },
           "fit {dir}/p.json -o {dir}/nodir/m.json --plot {dir}/fit.png --report {dir}/rep.json",
           "nodir"},
      },
      "profile", "p.json", args, base);
}

// ---- profile CSV (lucent fit FILE.csv -o OUT) --------------------------------------------------
std::vector<BadCase> profile_csv_cases() {
  const std::string args = "fit {dir}/p.csv -o {dir}/m.json";
  const std::string head = "# ior=1.5\n";
  const auto csv = [](std::string text) { return bytes_file("p.csv", text); };
  return {
      {"csv_missing", nullptr, args, "p.csv: cannot open"},
      {"csv_empty", csv(""), args, "p.csv"},
      {"csv_header_only", csv(head + "r_mm,R_r,R_g,R_b\n"), args, "empty"},
      {"csv_no_r", csv(head + "r,R\n1,0.1\n"), args, "r_mm"},
      {"csv_duplicate_column", csv(head + "r_mm,R_r,R_r,R_b\n1,0.1,0.1,0.1\n"), args,
       "R_r appears twice"},
      {"csv_unnamed_column", csv(head + "r_mm,,R\n1,2,0.1\n"), args, "no name"},
      {"csv_short_row", csv(head + "r_mm,R\n1\n"), args, "expected 2 fields"},
      {"csv_word", csv(head + "r_mm,R\n1,abc\n"), args, "column R"},
      {"csv_nan", csv(head + "r_mm,R\n1,nan\n"), args, "column R"},
      {"csv_inf", csv(head + "r_mm,R\n1,inf\n"), args, "column R"},
      {"csv_negative_r", csv(head + "r_mm,R\n-1,0.1\n"), args, "r_mm"},
      {"csv_negative_se", csv(head + "r_mm,R,se\n1,0.1,-0.01\n"), args, "standard error"},
      {"csv_inner_beyond_outer",
       csv(head + "r_mm,r_inner_mm,r_outer_mm,R\n1,1.5,0.5,0.1\n"), args, "r_inner_mm"},
      {"csv_ior_zero", csv("# ior=0\nr_mm,R\n1,0.1\n"), args, "ior"},
      {"csv_ior_word", csv("# ior=abc\nr_mm,R\n1,0.1\n"), args, "ior=abc"},
      {"csv_quantity_foo", csv("# ior=1.5 quantity=foo\nr_mm,R\n1,0.1\n"), args, "quantity"},
      {"csv_incidence_95", csv("# ior=1.5 incidence_deg=95\nr_mm,R\n1,0.1\n"), args,
       "incidence_deg"},
      {"csv_no_ior", csv("r_mm,R\n1,0.1\n2,0.05\n"), args, "--ior"},
      {"csv_dev_zero", nullptr, "fit /dev/zero -o {dir}/m.json", "/dev/zero"},
      {"csv_overwrites_input",
       [](const fs::path& d) { write_file(d / "p.csv", read_bytes(world() / "radial.csv")); },
       "fit {dir}/p.csv -o {dir}/p.csv", "expected a file ending in .json"},
  };
}

// ---- BSSRDF configurations CSV (lucent profile --configs FILE) ---------------------------------
std::vector<BadCase> configs_cases() {
  const std::string args = "profile --material marble --configs {dir}/k.csv -o {dir}/out.csv";
  const std::string header = "xi_x,xi_y,xi_z,ni_x,ni_y,ni_z,wi_x,wi_y,wi_z,xo_x,xo_y,xo_z,no_x,no_y,no_z\n";
  const std::string row = "0,0,0,0,0,1,0,0,1,1,0,0,0,0,1\n";
  const auto csv = [](std::string text) { return bytes_file("k.csv", text); };
  return {
      {"configs_missing", nullptr, args, "k.csv"},
      {"configs_empty", csv(""), args, "k.csv"},
      {"configs_bad_header", csv("a,b,c\n1,2,3\n"), args, "k.csv"},
      {"configs_header_only", csv(header), args, "k.csv"},
      {"configs_short_row", csv(header + "0,0,0,0,0,1\n"), args, "line 2"},
      {"configs_long_row", csv(header + "0,0,0,0,0,1,0,0,1,1,0,0,0,0,1,9\n"), args, "line 2"},
      {"configs_word", csv(header + "0,0,0,0,0,one,0,0,1,1,0,0,0,0,1\n"), args, "line 2"},
      {"configs_nan", csv(header + "nan,0,0,0,0,1,0,0,1,1,0,0,0,0,1\n"), args, "line 2"},
      {"configs_inf", csv(header + "0,0,0,0,0,1,0,0,1,inf,0,0,0,0,1\n"), args, "line 2"},
      {"configs_normal_not_unit", csv(header + "0,0,0,0,0,2,0,0,1,1,0,0,0,0,1\n"), args,
       "line 2"},
      {"configs_light_not_unit", csv(header + "0,0,0,0,0,1,0,0,0,1,0,0,0,0,1\n"), args, "line 2"},
      {"configs_huge_position", csv(header + "0,0,0,0,0,1,0,0,1,1e300,0,0,0,0,1\n"), args,
       "line 2"},
      {"configs_second_row_bad", csv(header + row + "0,0,0,0,0,1,0,0,1,1,0,0,0,0\n"), args,
       "line 3"},
      {"configs_binary", csv(std::string("\0\1\2\3", 4)), args, "k.csv"},
      {"configs_dev_zero", nullptr,
       "profile --material marble --configs /dev/zero -o {dir}/out.csv", "/dev/zero"},
      {"configs_overwrites_input", csv(header + row),
       "profile --material marble --configs {dir}/k.csv -o {dir}/k.csv", "is an input"},
      {"configs_output_folder_missing", csv(header + row),
       "profile --material marble --configs {dir}/k.csv -o {dir}/nodir/out.csv", "nodir"},
  };
}

std::vector<BadCase> all_document_cases() {
  std::vector<BadCase> all;
  for (auto table : {material_cases(), capture_cases(), profile_json_cases(), profile_csv_cases(),
                     configs_cases()}) {
    all.insert(all.end(), table.begin(), table.end());
  }
  return all;
}

class BadDocuments : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadDocuments, AreRefusedCleanly) { expect_clean_refusal(GetParam()); }

INSTANTIATE_TEST_SUITE_P(Table, BadDocuments, ::testing::ValuesIn(all_document_cases()),
                         [](const auto& info) { return info.param.name; });

}  // namespace
}  // namespace lucent::testing
