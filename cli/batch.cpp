// Batch manifests, shards and summaries (batch.h).
#include "batch.h"

#include <algorithm>
#include <cstdio>
#include <cstdint>
#include <cctype>
#include <map>
#include <filesystem>
#include <sstream>

#include "lucent/core/error.h"
#include "lucent/core/json_file.h"

namespace lucent::cli {
namespace {

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) {
    const auto a = cell.find_first_not_of(" \t\r"), b = cell.find_last_not_of(" \t\r");
    out.push_back(a == std::string::npos ? "" : cell.substr(a, b - a + 1));
  }
  if (!line.empty() && line.back() == ',') out.push_back("");
  return out;
}

}  // namespace

std::vector<BatchRow> read_batch_manifest(const std::string& path) {
  std::string text = read_input_file(path, 64 << 20);
  if (text.rfind("\xEF\xBB\xBF", 0) == 0) text.erase(0, 3);  // a UTF-8 byte order mark
  const std::filesystem::path base = std::filesystem::path(path).parent_path();
  std::istringstream in(text);
  std::string line;
  std::vector<std::string> header;
  std::vector<BatchRow> rows;
  int number = 0;
  const std::vector<std::string> known{"input", "output", "ior", "model", "g", "name"};
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos || line[0] == '#') continue;
    const std::vector<std::string> cells = split_csv_line(line);
    const std::string where = path + ":" + std::to_string(number) + ": ";
    if (header.empty()) {
      header = cells;
      for (const std::string& h : header)
        if (std::find(known.begin(), known.end(), h) == known.end())
          throw Error(where + "column '" + h + "': expected input, output, ior, model, g or name");
      for (const char* need : {"input", "output"})
        if (std::find(header.begin(), header.end(), need) == header.end())
          throw Error(where + "the header needs an '" + need + "' column");
      continue;
    }
    if (cells.size() != header.size())
      throw Error(where + "expected " + std::to_string(header.size()) + " cells, found " +
                  std::to_string(cells.size()));
    BatchRow row;
    row.index = rows.size();
    for (std::size_t c = 0; c < cells.size(); ++c) {
      if (header[c] == "input" || header[c] == "output") {
        if (cells[c].empty()) throw Error(where + "column '" + header[c] + "': empty");
        const std::filesystem::path p(cells[c]);
        (header[c] == "input" ? row.input : row.output) =
            (p.is_absolute() ? p : base / p).lexically_normal().string();
      } else if (!cells[c].empty()) {
        row.options[header[c]] = cells[c];
      }
    }
    rows.push_back(row);
  }
  if (rows.empty()) throw Error(path + ": the manifest has no rows");
  return rows;
}

namespace {

// One file's name for comparisons: absolute, "." and ".." resolved, links followed where they exist.
std::string same_file_key(const std::string& path) {
  std::error_code ec;
  std::filesystem::path p = std::filesystem::weakly_canonical(std::filesystem::absolute(path), ec);
  if (ec) p = std::filesystem::absolute(path).lexically_normal();
  return p.string();
}

}  // namespace

void plan_batch_outputs(const std::vector<BatchRow>& rows, const std::string& manifest,
                        const std::string& summary, bool allow_outside) {
  std::map<std::string, std::size_t> outputs;  // key -> row
  std::map<std::string, std::size_t> inputs;
  for (const BatchRow& row : rows) inputs.emplace(same_file_key(row.input), row.index);
  const std::string summary_key = same_file_key(summary), manifest_key = same_file_key(manifest);
  std::filesystem::path base = std::filesystem::path(manifest_key).parent_path();
  const std::string base_text = (base / "").string();
  for (const BatchRow& row : rows) {
    const std::string where = manifest + ": row " + std::to_string(row.index + 1) + ": output '" +
                              row.output + "': ";
    const std::string key = same_file_key(row.output);
    std::string ext = std::filesystem::path(row.output).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return std::tolower(ch); });
    if (ext != ".json") throw Error(where + "expected a .json material file");
    if (const auto [it, fresh] = outputs.emplace(key, row.index); !fresh)
      throw Error(where + "row " + std::to_string(it->second + 1) +
                  " writes the same file: each row needs its own output");
    if (key == summary_key) throw Error(where + "the same file as the summary (-o)");
    if (key == manifest_key) throw Error(where + "the manifest itself");
    if (const auto it = inputs.find(key); it != inputs.end())
      throw Error(where + "row " + std::to_string(it->second + 1) + "'s input: inputs are never "
                  "replaced");
    if (!allow_outside && key.rfind(base_text, 0) != 0)
      throw Error(where + "outside the manifest's folder " + base.string() +
                  " (give --allow-outside if that is meant)");
  }
}

void check_distinct_outputs(const std::vector<std::pair<std::string, std::string>>& outputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (!outputs[i].second.empty() && !outputs[j].second.empty() &&
          same_file_key(outputs[i].second) == same_file_key(outputs[j].second))
        throw Error(outputs[i].first + ": the same file as " + outputs[j].first + " (" +
                    outputs[i].second + "): each output needs its own file");
}

std::pair<int, int> parse_shard(const std::string& text, const std::string& option) {
  const auto slash = text.find('/');
  try {
    if (slash == std::string::npos) throw std::invalid_argument(text);
    std::size_t u1 = 0, u2 = 0;
    const std::string a = text.substr(0, slash), b = text.substr(slash + 1);
    const int i = std::stoi(a, &u1), n = std::stoi(b, &u2);
    if (u1 != a.size() || u2 != b.size() || n < 1 || i < 0 || i >= n)
      throw std::invalid_argument(text);
    return {i, n};
  } catch (const std::exception&) {
    throw Error(option + ": expected I/N with 0 <= I < N (shard I of N), got '" + text + "'");
  }
}

std::string file_hash(const std::string& path) {
  std::uint64_t h = 1469598103934665603ull;
  for (const unsigned char ch : read_input_file(path, 64 << 20)) h = (h ^ ch) * 1099511628211ull;
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}

nlohmann::json batch_summary(const std::string& manifest, std::size_t manifest_rows,
                             const std::vector<BatchOutcome>& outcomes, const std::string& shard,
                             const nlohmann::json& run) {
  nlohmann::json rows = nlohmann::json::array();
  for (const BatchOutcome& o : outcomes) {
    nlohmann::json r = {{"index", o.row.index},
                        {"input", o.row.input},
                        {"output", o.row.output},
                        {"status", o.ok ? "ok" : "failed"}};
    if (!o.ok) {
      r["error"] = o.error;
    } else {
      r["model"] = o.material.model;
      r["ior"] = o.material.ior;
      r["sigma_a"] = o.material.sigma_a;
      r["sigma_s_reduced"] = o.material.sigma_s_reduced;
      if (o.material.uncertainty.is_object() && o.material.uncertainty.contains("sigma_a")) {
        r["sd_sigma_a"] = o.material.uncertainty["sigma_a"];
        r["sd_sigma_s_reduced"] = o.material.uncertainty["sigma_s_reduced"];
      }
    }
    rows.push_back(r);
  }
  nlohmann::json doc = {{"format", "lucent-batch-summary"},
                        {"version", 1},
                        {"manifest", manifest},
                        {"manifest_rows", manifest_rows},
                        {"run", run},
                        {"rows", rows}};
  if (!shard.empty()) doc["shard"] = shard;
  return doc;
}

nlohmann::json merge_batch_summaries(const std::vector<nlohmann::json>& shards,
                                     const std::vector<std::string>& sources) {
  if (shards.empty()) throw Error("merge: no summaries given");
  const auto field = [&](std::size_t i, const char* name) -> const nlohmann::json& {
    if (!shards[i].is_object() || !shards[i].contains(name))
      throw Error(sources[i] + ": field '" + name + "': missing (not a lucent-batch-summary?)");
    return shards[i].at(name);
  };
  const nlohmann::json manifest = field(0, "manifest");
  const nlohmann::json count = field(0, "manifest_rows");
  const nlohmann::json run = field(0, "run");
  if (!count.is_number_unsigned()) throw Error(sources[0] + ": field 'manifest_rows': expected a count");
  // The rows the shards hold, counted before anything is sized by the claimed count (a 559-byte
  // summary claiming 1e8 rows took 1.6 GB).
  std::size_t held = 0;
  for (std::size_t i = 0; i < shards.size(); ++i) {
    if (field(i, "format") != "lucent-batch-summary")
      throw Error(sources[i] + ": format: expected \"lucent-batch-summary\"");
    if (field(i, "manifest") != manifest || field(i, "manifest_rows") != count)
      throw Error(sources[i] + ": manifest: another manifest than " + sources[0] + "'s");
    if (field(i, "run") != run)
      throw Error(sources[i] + ": run: fitted with other options or from an edited manifest than " +
                  sources[0] + " (its 'run' differs): rerun the shards alike");
    if (!field(i, "rows").is_array()) throw Error(sources[i] + ": rows: expected an array");
    held += field(i, "rows").size();
  }
  if (count.get<std::uint64_t>() != held)
    throw Error(sources[0] + ": manifest_rows: " + count.dump() + " rows claimed, the shards hold " +
                std::to_string(held) + " (a shard missing, or given twice)");
  std::vector<nlohmann::json> rows(held);
  std::vector<bool> seen(rows.size(), false);
  std::vector<std::size_t> from(rows.size(), 0);
  for (std::size_t i = 0; i < shards.size(); ++i) {
    for (const nlohmann::json& r : field(i, "rows")) {
      if (!r.is_object() || !r.contains("index") || !r["index"].is_number_unsigned() ||
          r["index"].get<std::uint64_t>() >= rows.size())
        throw Error(sources[i] + ": rows: an index outside the manifest");
      const std::size_t k = r["index"].get<std::size_t>();
      if (seen[k])
        throw Error(sources[i] + ": rows: row " + std::to_string(k) + " also in " + sources[from[k]]);
      seen[k] = true;
      from[k] = i;
      rows[k] = r;
    }
  }
  for (std::size_t k = 0; k < rows.size(); ++k)
    if (!seen[k])
      throw Error(sources[0] + ": row " + std::to_string(k) + " of the manifest is in none of the " +
                  std::to_string(shards.size()) + " shards");
  nlohmann::json doc = {{"format", "lucent-batch-summary"},
                        {"version", 1},
                        {"manifest", manifest},
                        {"manifest_rows", count},
                        {"run", run},
                        {"rows", rows}};
  return doc;
}

}  // namespace lucent::cli
