// Atomic output (docs/DESIGN.md §2): every file and folder a run writes appears whole or not at
// all.
//
// Each output is first written to a hidden temporary beside its target (`.NAME.tmp-PID-N[.ext]`,
// same file system, so rename(2) is atomic). Without an OutputTransaction each output is renamed
// into place when it is complete. Inside one (every CLI command runs in one), the renames wait for
// OutputTransaction::commit(), which makes them all (backing up replaced targets and restoring them
// if any rename fails): a command that fails, throws, or is stopped by SIGINT/SIGTERM/SIGHUP leaves
// none of its outputs and none of its temporaries. Temporaries left by a process that was killed
// (SIGKILL) are removed the next time lucent writes into that folder.
//
// Inputs are protected too: readers record what they read (note_input), and an output that would
// replace a recorded input, or a folder holding one, is refused.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace lucent {

/// Records that this run read `path` (readers call it) while an OutputTransaction is open. Outputs
/// that name the same file, or an output folder that holds it, are then refused (lucent::Error).
void note_input(const std::filesystem::path& path);

/// Throws lucent::Error if writing `target` would replace an input this run read.
void check_not_an_input(const std::filesystem::path& target);

/// Throws lucent::Error "<path>: cannot write: the folder F does not exist" unless the folder that
/// would hold `path` exists (commands call it first, so that a typo fails before the work).
void check_output_folder(const std::filesystem::path& path);

/// check_output_folder, and that `path` names a file (not "", ".", "/" or an existing folder)
/// ending in `extension` (case-insensitive; empty: any). `option` names it in the error.
void check_output_file(const std::filesystem::path& path, const std::string& extension,
                       const std::string& option);

/// Writes `content` to `path` atomically. Text (binary = false) is checked first: a "nan" or
/// "inf" number token is refused (lucent never writes one). Throws lucent::Error naming the path.
void write_file_atomically(const std::filesystem::path& path, std::string_view content,
                           bool binary = false);

/// For writers that need a file name (image libraries): hands out a temporary path in the target's
/// folder; commit() renames it over the target (or hands it to the open transaction); the
/// destructor removes it if commit() was not called.
class AtomicOutputPath {
 public:
  explicit AtomicOutputPath(std::filesystem::path target);
  ~AtomicOutputPath();
  AtomicOutputPath(const AtomicOutputPath&) = delete;
  AtomicOutputPath& operator=(const AtomicOutputPath&) = delete;

  /// Where to write. Keeps the target's extension so format-sniffing writers still work.
  const std::filesystem::path& temporary() const { return temporary_; }
  const std::filesystem::path& target() const { return target_; }
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temporary_;
  bool committed_ = false;
};

/// An output folder that appears whole or not at all: files are written into a temporary sibling
/// folder; commit() renames it to the target. A target that exists and is not empty is replaced
/// whole, and only when the run allows it (set_replace_folders, the CLI's --force); never when it
/// holds an input of the run. The destructor removes the temporary folder if commit() was not
/// called, leaving the target exactly as it was.
class AtomicOutputDir {
 public:
  explicit AtomicOutputDir(std::filesystem::path target);
  ~AtomicOutputDir();
  AtomicOutputDir(const AtomicOutputDir&) = delete;
  AtomicOutputDir& operator=(const AtomicOutputDir&) = delete;

  /// Where to write: `temporary() / name` for each file.
  const std::filesystem::path& temporary() const { return temporary_; }
  const std::filesystem::path& target() const { return target_; }
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temporary_;
  bool committed_ = false;
};

/// Whether an existing, non-empty output folder may be replaced (whole). Off by default.
void set_replace_folders(bool allow);

/// All the outputs of one command as one commit. At most one is open at a time; while it is, the
/// helpers above defer their renames to commit(). Destroyed without commit(): every temporary is
/// removed and no target is touched.
class OutputTransaction {
 public:
  OutputTransaction();
  ~OutputTransaction();
  OutputTransaction(const OutputTransaction&) = delete;
  OutputTransaction& operator=(const OutputTransaction&) = delete;

  /// Renames every output into place, all or none: if one rename fails the targets already
  /// replaced are restored from their backups before the error is thrown.
  void commit();
};

/// While one is alive (in this thread), the atomic writers above rename into place at once even
/// with a transaction open: for cache entries, which are not a run's outputs (a run that fails
/// later keeps them, and writing them commits none of the run's outputs).
class CacheWriteScope {
 public:
  CacheWriteScope();
  ~CacheWriteScope();
  CacheWriteScope(const CacheWriteScope&) = delete;
  CacheWriteScope& operator=(const CacheWriteScope&) = delete;
};

/// A warning for stderr (one line, without the trailing newline). While a transaction is open it
/// waits for the commit, so that a run that fails prints its one error line and nothing else;
/// without one it is printed at once.
void warn(const std::string& line);

/// Commits what the open transaction holds so far (the viewer's screenshots appear at once);
/// OutputTransaction::commit() calls it. Without a transaction there is nothing pending.
void commit_pending_outputs();

/// Blocks SIGINT, SIGTERM and SIGHUP in the calling thread (call it first in main, before any
/// thread starts, so that every thread inherits the mask) and starts a thread that waits for them:
/// on one it removes every temporary of this process, then lets the signal end the process as it
/// would have (exit status 128 + signal).
void remove_temporaries_on_signals();

}  // namespace lucent
