// Atomic output (DESIGN §2: "outputs written atomically: a failed run leaves no partial file").
// Both helpers put the temporary file in the target's own folder, because rename(2) is atomic only
// within one file system; a temporary in /tmp could not be renamed over a target on another mount.
#include "lucent/materials/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>

#include "lucent/materials/error.h"

namespace lucent {
namespace {

// Distinguishes temporaries of one process (several writers, or threads, aiming at one folder);
// the pid distinguishes processes.
std::atomic<unsigned long> g_temporary_counter{0};

std::string temporary_suffix() {
  return ".tmp-" + std::to_string(static_cast<long>(::getpid())) + "-" +
         std::to_string(g_temporary_counter.fetch_add(1));
}

[[noreturn]] void fail(const std::filesystem::path& target, const std::string& what, int err) {
  throw Error(target.string() + ": cannot write: " + what + ": " + std::strerror(err));
}

}  // namespace

void write_file_atomically(const std::filesystem::path& path, std::string_view content) {
  const std::filesystem::path temporary = path.string() + temporary_suffix();

  // POSIX calls rather than std::ofstream: a stream only reports "failed", while the user needs the
  // reason (no such folder, permission denied, disk full). O_EXCL: never reuse someone else's file.
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) fail(path, "cannot create temporary file " + temporary.string(), errno);

  auto discard = [&](const std::string& what, int err) {
    ::close(fd);
    ::unlink(temporary.c_str());
    fail(path, what, err);
  };

  const char* data = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t written = ::write(fd, data, left);
    if (written < 0) {
      if (errno == EINTR) continue;
      discard("write failed", errno);
    }
    data += written;
    left -= static_cast<std::size_t>(written);
  }
  // close() is where some file systems (NFS, quota) report a failed write; check it too.
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(temporary.c_str());
    fail(path, "close failed", err);
  }

  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw Error(path.string() + ": cannot write: rename from " + temporary.string() +
                " failed: " + ec.message());
  }
}

AtomicOutputPath::AtomicOutputPath(std::filesystem::path target) : target_(std::move(target)) {
  // A hidden name (leading '.') so that a crash leaves nothing that looks like a result; the
  // extension stays last so that writers choosing the format from the name still see it.
  const std::string name =
      "." + target_.stem().string() + temporary_suffix() + target_.extension().string();
  temporary_ = target_.parent_path() / name;
}

AtomicOutputPath::~AtomicOutputPath() {
  if (committed_) return;
  std::error_code
      ignored;  // a destructor must not throw; there is nothing to remove if never written
  std::filesystem::remove(temporary_, ignored);
}

void AtomicOutputPath::commit() {
  if (committed_) return;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(temporary_, ec)) {
    throw Error(target_.string() + ": cannot write: the temporary file " + temporary_.string() +
                " was not written");
  }
  std::filesystem::rename(temporary_, target_, ec);
  if (ec) {
    throw Error(target_.string() + ": cannot write: rename from " + temporary_.string() +
                " failed: " + ec.message());
  }
  committed_ = true;
}

AtomicOutputDir::AtomicOutputDir(std::filesystem::path target) : target_(std::move(target)) {
  std::filesystem::path parent = target_.parent_path();
  if (parent.empty()) parent = ".";
  if (!std::filesystem::is_directory(parent)) {
    throw Error(target_.string() + ": cannot write: the folder " + parent.string() +
                " does not exist");
  }
  if (std::filesystem::exists(target_) && !std::filesystem::is_directory(target_)) {
    throw Error(target_.string() + ": cannot write: exists and is not a folder");
  }
  const std::string name = target_.filename().empty() ? target_.parent_path().filename().string()
                                                      : target_.filename().string();
  temporary_ = parent / ("." + name + temporary_suffix());
  std::error_code ec;
  std::filesystem::create_directory(temporary_, ec);
  if (ec) throw Error(target_.string() + ": cannot write: " + ec.message());
}

AtomicOutputDir::~AtomicOutputDir() {
  if (!committed_) {
    std::error_code ignored;
    std::filesystem::remove_all(temporary_, ignored);
  }
}

void AtomicOutputDir::commit() {
  std::error_code ec;
  if (!std::filesystem::exists(target_)) {
    std::filesystem::rename(temporary_, target_, ec);
    if (ec) throw Error(target_.string() + ": cannot write: " + ec.message());
  } else {
    for (const auto& entry : std::filesystem::directory_iterator(temporary_)) {
      std::filesystem::rename(entry.path(), target_ / entry.path().filename(), ec);
      if (ec)
        throw Error((target_ / entry.path().filename()).string() +
                    ": cannot write: " + ec.message());
    }
    std::filesystem::remove_all(temporary_, ec);
  }
  committed_ = true;
}

}  // namespace lucent
