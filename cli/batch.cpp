// Batch manifests, shards and summaries (batch.h).
#include "batch.h"

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "lucent/materials/error.h"
#include "lucent/materials/json_file.h"

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
  const std::string text = read_input_file(path, 64 << 20);
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

nlohmann::json batch_summary(const std::string& manifest, std::size_t manifest_rows,
                             const std::vector<BatchOutcome>& outcomes, const std::string& shard) {
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
  if (!count.is_number_unsigned()) throw Error(sources[0] + ": field 'manifest_rows': expected a count");
  std::vector<nlohmann::json> rows(count.get<std::size_t>());
  std::vector<bool> seen(rows.size(), false);
  for (std::size_t i = 0; i < shards.size(); ++i) {
    if (field(i, "format") != "lucent-batch-summary")
      throw Error(sources[i] + ": format: expected \"lucent-batch-summary\"");
    if (field(i, "manifest") != manifest || field(i, "manifest_rows") != count)
      throw Error(sources[i] + ": manifest: another manifest than " + sources[0] + "'s");
    for (const nlohmann::json& r : field(i, "rows")) {
      if (!r.is_object() || !r.contains("index") || !r["index"].is_number_unsigned() ||
          r["index"].get<std::size_t>() >= rows.size())
        throw Error(sources[i] + ": rows: an index outside the manifest");
      const std::size_t k = r["index"].get<std::size_t>();
      if (seen[k]) throw Error(sources[i] + ": rows: row " + std::to_string(k) + " given twice");
      seen[k] = true;
      rows[k] = r;
    }
  }
  for (std::size_t k = 0; k < rows.size(); ++k)
    if (!seen[k]) throw Error("merge: row " + std::to_string(k) + " of the manifest is in no shard");
  nlohmann::json doc = {{"format", "lucent-batch-summary"},
                        {"version", 1},
                        {"manifest", manifest},
                        {"manifest_rows", count},
                        {"rows", rows}};
  return doc;
}

}  // namespace lucent::cli
