// Atomic output: write to a temporary file beside the target, rename over it when complete, so a
// failed run never leaves a partial file behind.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace lucent {

/// Writes `content` to `path` atomically (temporary file in the same folder + rename).
/// Throws lucent::Error naming the path when it cannot.
void write_file_atomically(const std::filesystem::path& path, std::string_view content);

/// For writers that need a file name (image libraries): hands out a temporary path in the target's
/// folder; commit() renames it over the target; the destructor removes it if commit() was not
/// called.
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
/// folder; commit() renames it to the target (or, when the target already exists, moves each file
/// into it, replacing files of the same name); the destructor removes the temporary folder if
/// commit() was not called, leaving the target exactly as it was.
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

}  // namespace lucent
