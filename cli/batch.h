// Batch fits (`lucent fit --batch MANIFEST [--shard I/N]`) and the merge of their shards
// (`lucent merge`): the manifest, the shard selection and the summaries (no CLI11 here).
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "lucent/materials/material.h"

namespace lucent::cli {

/// One manifest row: a profile to fit and the material file to write, with per-row options.
struct BatchRow {
  std::size_t index = 0;  ///< 0-based row number (the data rows, header excluded)
  std::string input, output;
  std::map<std::string, std::string> options;  ///< "ior", "model", "g", "name" when given
};

/// Reads a manifest: a CSV whose header has `input` and `output` and optionally `ior`, `model`,
/// `g`, `name`; relative paths are taken from the manifest's folder; `#` lines and blank lines
/// are skipped. Throws lucent::Error naming the file, line and column.
std::vector<BatchRow> read_batch_manifest(const std::string& path);

/// "I/N" -> (I, N), 0 <= I < N; throws lucent::Error naming `option`.
/// Plans a batch's outputs before any is written (every row, not only a shard's: shards write into
/// one tree): refused, naming the rows, are two rows with one output, a row whose output is the
/// summary, the manifest or any row's input, an output that is not a .json file, and (unless
/// allow_outside) one outside the manifest's folder.
void plan_batch_outputs(const std::vector<BatchRow>& rows, const std::string& manifest,
                        const std::string& summary, bool allow_outside);

/// Throws lucent::Error when two of the named outputs (option, path; empty paths skipped) are one
/// file: "--report: the same file as -o (X)".
void check_distinct_outputs(const std::vector<std::pair<std::string, std::string>>& outputs);

std::pair<int, int> parse_shard(const std::string& text, const std::string& option);

/// One row's outcome, for the summary.
struct BatchOutcome {
  BatchRow row;
  bool ok = false;
  std::string error;
  materials::Material material;  ///< when ok
};

/// The summary of a run (or of one shard: `shard` "I/N", empty for all rows): format
/// "lucent-batch-summary", the manifest, the rows in order with their status and coefficients.
/// Deterministic: a merge of every shard's summary equals the unsharded run's.
/// `run` says what the rows were fitted with (the options, the manifest's FNV-1a hash): shards
/// merge only when theirs agree.
nlohmann::json batch_summary(const std::string& manifest, std::size_t manifest_rows,
                             const std::vector<BatchOutcome>& outcomes, const std::string& shard,
                             const nlohmann::json& run);

/// FNV-1a 64 of a file's bytes, as 16 hex digits (the manifest's identity in a summary).
std::string file_hash(const std::string& path);

/// Joins shard summaries into the summary of the whole manifest: every row exactly once, the same
/// manifest. Throws lucent::Error naming what does not match or is missing.
nlohmann::json merge_batch_summaries(const std::vector<nlohmann::json>& shards,
                                     const std::vector<std::string>& sources);

}  // namespace lucent::cli
