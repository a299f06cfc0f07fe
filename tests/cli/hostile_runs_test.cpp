// Hostile and careless runs, one table per class (issue "Nothing lost, nothing trusted blindly"):
// a batch's outputs planned before any is written and committed together (an interrupted batch
// leaves none), shard summaries merged only when they are one run's, the cache's odd entries never
// fatal. Each refusal: exit 1 or 2, one stderr line naming the culprit, nothing written, no
// temporary, no input changed, bounded memory and time (bad_input.h).
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <thread>

#include "bad_input.h"
#include "lucent/materials/transport_table.h"

namespace lucent::testing {
namespace {

// ---- batch outputs ------------------------------------------------------------------------------

// A manifest in the case's folder; "{profile}" becomes the world's profile.
std::function<void(const fs::path&)> manifest(std::string text, std::string name = "m.csv") {
  return [=](const fs::path& dir) {
    write_file(dir / name, replace_all(text, "{profile}", (world() / "acq/profile.json").string()));
  };
}

std::vector<BadCase> batch_cases() {
  const std::string batch = "fit --batch {dir}/m.csv --quality fast -o {dir}/summary.json";
  const std::string head = "input,output\n";
  return {
      {"two_rows_one_output", manifest(head + "{profile},a.json\n{profile},a.json\n"), batch,
       "row 1 writes the same file"},
      {"one_output_spelt_two_ways", manifest(head + "{profile},a.json\n{profile},./sub/../a.json\n"),
       batch, "writes the same file"},
      {"row_output_is_the_summary", manifest(head + "{profile},summary.json\n"), batch,
       "the same file as the summary"},
      {"row_output_is_the_manifest", manifest(head + "{profile},m.csv\n"), batch,
       "expected a .json"},
      {"row_output_is_the_manifest_json",
       [](const fs::path& dir) {
         write_file(dir / "m.json", "input,output\n" + (world() / "acq/profile.json").string() +
                                        ",m.json\n");
       },
       "fit --batch {dir}/m.json -o {dir}/summary.json", "the manifest itself"},
      {"row_output_is_its_input",
       [](const fs::path& dir) {
         fs::copy_file(world() / "acq/profile.json", dir / "p.json");
         write_file(dir / "m.csv", "input,output\np.json,p.json\n");
       },
       batch, "inputs are never replaced"},
      {"row_output_is_another_rows_input",
       [](const fs::path& dir) {
         fs::copy_file(world() / "acq/profile.json", dir / "p.json");
         write_file(dir / "m.csv", "input,output\np.json,a.json\n" +
                                       (world() / "acq/profile.json").string() + ",p.json\n");
       },
       batch, "row 1's input"},
      {"row_output_outside_the_folder", manifest(head + "{profile},../outside/victim.json\n"), batch,
       "outside the manifest's folder"},
      {"row_output_absolute_elsewhere", manifest(head + "{profile},/tmp/lucent-victim.json\n"),
       batch, "--allow-outside"},
      {"row_output_not_json", manifest(head + "{profile},a.txt\n"), batch, "expected a .json"},
      {"row_output_empty", manifest(head + "{profile},\n"), batch, "column 'output': empty"},
      {"manifest_header_only", manifest(head), batch, "no rows"},
      {"manifest_unknown_column", manifest("input,output,colour\n{profile},a.json,red\n"), batch,
       "column 'colour'"},
      {"manifest_cell_count", manifest(head + "{profile},a.json,extra\n"), batch, "cells"},
      {"summary_is_a_row_input",
       [](const fs::path& dir) {
         fs::copy_file(world() / "acq/profile.json", dir / "p.json");
         write_file(dir / "m.csv", "input,output\np.json,a.json\n");
       },
       "fit --batch {dir}/m.csv -o {dir}/p.json", "p.json"},
      {"report_is_the_material", nullptr,
       "fit {world}/acq/profile.json -o {dir}/m.json --report {dir}/m.json", "--report"},
      {"report_is_the_material_spelt_otherwise", nullptr,
       "fit {world}/acq/profile.json -o {dir}/m.json --report {dir}/./m.json", "--report"},
  };
}

class BatchOutputs : public ::testing::TestWithParam<BadCase> {};
TEST_P(BatchOutputs, AreRefusedBeforeAnyIsWritten) { expect_clean_refusal(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Table, BatchOutputs, ::testing::ValuesIn(batch_cases()),
                         [](const auto& info) { return info.param.name; });


// ---- merge ----------------------------------------------------------------------------------------

// A shard summary: rows with these indices, of a manifest of `count` rows fitted with `options`.
std::string summary(const std::string& count, std::vector<int> rows, const std::string& options,
                    bool with_run = true) {
  std::string r;
  for (const int i : rows)
    r += std::string(r.empty() ? "" : ",") + "{\"index\": " + std::to_string(i) +
         ", \"input\": \"p.json\", \"output\": \"o" + std::to_string(i) +
         ".json\", \"status\": \"failed\", \"error\": \"x\"}";
  return "{\"format\": \"lucent-batch-summary\", \"version\": 1, \"manifest\": \"m.csv\", "
         "\"manifest_rows\": " + count + ", " +
         (with_run ? "\"run\": {\"manifest_fnv1a\": \"0\", \"options\": " + options + "}, " : "") +
         "\"rows\": [" + r + "]}";
}

std::function<void(const fs::path&)> shards(std::string a, std::string b) {
  return [=](const fs::path& dir) {
    write_file(dir / "a.json", a);
    write_file(dir / "b.json", b);
  };
}

std::vector<BadCase> merge_cases() {
  const std::string merge = "merge {dir}/a.json {dir}/b.json -o {dir}/all.json";
  const std::string same = "{\"model\": \"auto\"}";
  return {
      {"other_options", shards(summary("2", {0}, same), summary("2", {1}, "{\"model\": \"dipole\"}")),
       merge, "b.json: run: fitted with other options"},
      {"claims_1e8_rows", shards(summary("100000000", {0}, same), summary("100000000", {1}, same)),
       merge, "a.json: manifest_rows: 100000000 rows claimed, the shards hold 2"},
      {"claims_1e19_rows",
       shards(summary("10000000000000000000", {0}, same), summary("10000000000000000000", {1}, same)),
       merge, "manifest_rows"},
      {"claims_fewer_rows", shards(summary("1", {0}, same), summary("1", {1}, same)), merge,
       "manifest_rows"},
      {"a_row_twice", shards(summary("2", {0}, same), summary("2", {0}, same)), merge,
       "b.json: rows: row 0 also in"},
      {"no_run", shards(summary("2", {0}, same, false), summary("2", {1}, same, false)), merge,
       "a.json: field 'run'"},
      {"other_manifest",
       shards(summary("2", {0}, same),
              replace_all(summary("2", {1}, same), "\"m.csv\"", "\"n.csv\"")),
       merge, "b.json: manifest"},
      {"not_a_summary", shards("{\"format\": \"x\"}", summary("2", {1}, same)), merge, "a.json"},
      {"rows_not_an_array",
       shards(replace_all(summary("2", {0}, same), "\"rows\": [", "\"rows\": {\"x\": ["), summary("2", {1}, same)),
       merge, "a.json"},
      {"index_outside", shards(summary("2", {0}, same), summary("2", {7}, same)), merge,
       "b.json: rows: an index outside"},
      {"negative_count", shards(summary("-2", {0}, same), summary("-2", {1}, same)), merge,
       "a.json: field 'manifest_rows'"},
      {"text_not_json", shards("rows: 2", summary("2", {1}, same)), merge, "a.json"},
      {"count_a_string", shards(summary("\"2\"", {0}, same), summary("\"2\"", {1}, same)), merge,
       "a.json: field 'manifest_rows'"},
      {"index_a_string",
       shards(replace_all(summary("2", {0}, same), "\"index\": 0", "\"index\": \"0\""),
              summary("2", {1}, same)),
       merge, "a.json: rows"},
      {"row_not_an_object",
       shards(replace_all(summary("2", {0}, same), "\"rows\": [{", "\"rows\": [7, {"),
              summary("2", {1}, same)),
       merge, "the shards hold 3"},
  };
}

class MergeSummaries : public ::testing::TestWithParam<BadCase> {};
TEST_P(MergeSummaries, AreRefusedNamingTheShard) { expect_clean_refusal(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Table, MergeSummaries, ::testing::ValuesIn(merge_cases()),
                         [](const auto& info) { return info.param.name; });


// ---- the cache ----------------------------------------------------------------------------------

// The cache's odd entries are never fatal and never block: every case runs a fit at a g the shipped
// table lacks (it looks for the slice in the cache, then builds it at 1e4 photons: a second or two)
// and must exit 0, with a warning where the entry was odd, and leave a readable slice where it
// replaced one.
struct CacheCase {
  std::string name;
  /// Prepares the cache folder `cache` (not yet made) whose slice is called `slice`.
  std::function<void(const fs::path& cache, const std::string& slice)> setup;
  bool warned = true;     // a warning on stderr
  bool replaced = false;  // afterwards the slice is a regular file lucent reads
};
void PrintTo(const CacheCase& c, std::ostream* os) { *os << c.name; }

const std::string& fit_at_g095() {
  static const std::string fit = "fit \"" + (world() / "acq/profile.json").string() +
                                 "\" --g 0.95 --table-photons 10000 --quality fast -q -o ";
  return fit;
}

CommandResult fit_with_cache(const fs::path& cache, const fs::path& out) {
  ::setenv("LUCENT_CACHE_DIR", cache.c_str(), 1);
  // Bounded as the refusals are: a FIFO opened would hang, /dev/zero read whole would exhaust memory.
  const CommandResult r = run_lucent(fit_at_g095() + "\"" + out.string() + "\"", "cache", kRefusalLimits);
  ::unsetenv("LUCENT_CACHE_DIR");
  return r;
}

// The slice's file name and a good copy of it, from one build in a fresh cache.
const std::pair<std::string, std::string>& good_slice() {
  static const std::pair<std::string, std::string> slice = [] {
    const fs::path dir = scratch_dir("hostile-cache-learn");
    const CommandResult r = fit_with_cache(dir / "cache", dir / "m.json");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    std::pair<std::string, std::string> found;
    for (const auto& e : fs::directory_iterator(dir / "cache"))
      found = {e.path().filename().string(), read_bytes(e.path())};
    return found;
  }();
  return slice;
}

std::vector<CacheCase> cache_cases() {
  using P = const fs::path&;
  using S = const std::string&;
  const auto made = [](P c) { fs::create_directories(c); };
  return {
      {"fifo_under_the_slices_name", [=](P c, S n) { made(c), ::mkfifo((c / n).c_str(), 0644); }, true, true},
      {"fifo_named_like_another_slice",
       [=](P c, S n) { made(c), ::mkfifo((c / replace_all(n, "n10000", "n20000")).c_str(), 0644); }, false, false},
      {"device_under_the_slices_name", [=](P c, S n) { made(c), fs::create_symlink("/dev/zero", c / n); }, true, true},
      {"dangling_link", [=](P c, S n) { made(c), fs::create_symlink(c / "nowhere.lut", c / n); }, true, true},
      {"folder_under_the_slices_name", [=](P c, S n) { fs::create_directories(c / n); }, true, false},
      {"cache_folder_a_loop", [](P c, S) { fs::create_directories(c.parent_path()), fs::create_directory_symlink(c, c); }, true, false},
      {"cache_folder_a_file", [](P c, S) { fs::create_directories(c.parent_path()), write_file(c, "a file"); }, true, false},
      {"cache_folder_under_a_file",
       [](P c, S) { fs::create_directories(c.parent_path().parent_path()), write_file(c.parent_path(), "x"); },
       true, false},
      {"garbage_entry", [=](P c, S n) { made(c), write_file(c / n, "garbage\n"); }, true, true},
      {"empty_entry", [=](P c, S n) { made(c), write_file(c / n, ""); }, true, true},
      {"truncated_entry",
       [=](P c, S n) { made(c), write_file(c / n, good_slice().second.substr(0, good_slice().second.size() / 2)); },
       true, true},
      {"entry_with_zero_radius_bins",
       [=](P c, S n) {
         made(c);
         const std::string& b = good_slice().second;
         const std::size_t nl = b.find('\n');
         nlohmann::json h = nlohmann::json::parse(b.substr(0, nl));
         h["grid"]["rho_max"] = h["grid"]["rho_min"].get<double>() * 1.0001;
         write_file(c / n, h.dump() + "\n" + b.substr(nl + 1));
       },
       true, true},
      {"entry_of_another_eta",
       [=](P c, S n) {
         made(c);
         std::string b = good_slice().second;
         const std::size_t nl = b.find('\n');
         nlohmann::json h = nlohmann::json::parse(b.substr(0, nl));
         h["slices"][0]["eta"] = 2.2;
         write_file(c / n, h.dump() + "\n" + b.substr(nl + 1));
       },
       false, true},
      {"good_entry_through_a_link",
       [=](P c, S n) {
         made(c);
         write_file(c.parent_path() / "elsewhere.lut", good_slice().second);
         fs::create_symlink(c.parent_path() / "elsewhere.lut", c / n);
       },
       false, true},
      {"good_entry", [=](P c, S n) { made(c), write_file(c / n, good_slice().second); }, false, true},
  };
}

class CacheEntries : public ::testing::TestWithParam<CacheCase> {};
TEST_P(CacheEntries, AreNeverFatalAndOddOnesAreReplaced) {
  const CacheCase& c = GetParam();
  const std::string slice = good_slice().first;
  ASSERT_FALSE(slice.empty());
  const fs::path dir = scratch_dir("hostile-cache-" + c.name);
  const fs::path cache = dir / "sub" / "cache";
  c.setup(cache, slice);
  const CommandResult r = fit_with_cache(cache, dir / "m.json");
  EXPECT_EQ(r.exit_code, 0) << c.name << ": " << r.err;
  EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(dir / "m.json")) << c.name;
  if (c.warned) {
    EXPECT_NE(r.err.find("warning"), std::string::npos) << c.name << ": " << r.err;
  }
  if (c.replaced) {
    std::error_code ec;
    EXPECT_TRUE(fs::is_regular_file(cache / slice, ec)) << c.name;
    EXPECT_NO_THROW((void)lucent::materials::read_transport_table(cache / slice)) << c.name;
  }
  fs::remove_all(dir);
}
INSTANTIATE_TEST_SUITE_P(Table, CacheEntries, ::testing::ValuesIn(cache_cases()),
                         [](const auto& info) { return info.param.name; });

// ---- an interrupted batch ------------------------------------------------------------------------

// SIGINT after the first row has built a transport-table slice (its cache write commits at once,
// apart from the run's outputs): the batch leaves no row output, no summary and no temporary; the
// cache keeps the slice, whole. Each row fits at a g the shipped table lacks, so each builds a slice
// (1e5 photons: seconds each), and the signal lands while the second is being built.
TEST(InterruptedBatch, LeavesNoRowOutputsAndNoSummary) {
  const fs::path dir = scratch_dir("hostile-batch-sigint");
  const fs::path cache = dir / "cache", out = dir / "out";
  fs::create_directories(out);
  std::string rows = "input,output,ior,g\n";
  for (const char* g : {"0.93", "0.94", "0.96"})
    rows += (world() / "acq/profile.json").string() + ",out/g" + g + ".json,1.3," + g + "\n";
  write_file(dir / "m.csv", rows);
  ::setenv("LUCENT_CACHE_DIR", cache.c_str(), 1);
  const pid_t pid =
      spawn_lucent("fit --batch \"" + (dir / "m.csv").string() + "\" --table-photons 100000 " +
                       "--quality fast -q -o \"" + (dir / "summary.json").string() + "\"",
                   dir / "log");
  ::unsetenv("LUCENT_CACHE_DIR");
  // Waits (up to 300 s) for the first slice to be in the cache, whole (not a temporary).
  const auto slices = [&] {
    std::vector<fs::path> found;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(cache, ec))
      if (e.path().extension() == ".lut" && e.path().filename().string().find(".tmp-") == std::string::npos)
        found.push_back(e.path());
    return found;
  };
  for (int i = 0; i < 3000 && slices().empty(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_EQ(slices().size(), 1u) << read_text(dir / "log");
  ::kill(pid, SIGINT);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGINT)
      << "status " << status << "; the batch ended before the signal? " << read_text(dir / "log");
  EXPECT_TRUE(fs::is_empty(out)) << "a row's output was committed by the cache write";
  EXPECT_FALSE(fs::exists(dir / "summary.json"));
  EXPECT_FALSE(has_temporary(dir));
  EXPECT_FALSE(has_temporary(out));
  ASSERT_EQ(slices().size(), 1u);
  EXPECT_NO_THROW((void)lucent::materials::read_transport_table(slices().front()));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace lucent::testing
