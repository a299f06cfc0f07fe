// Atomic output (docs/DESIGN.md §2). Temporaries live in the target's own folder, because rename(2)
// is atomic only within one file system. One process-wide registry knows every live temporary (for
// the signal thread and the transaction), every input read, and the renames a transaction defers.
#include "lucent/core/atomic_file.h"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <regex>
#include <set>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "lucent/core/error.h"

namespace fs = std::filesystem;

namespace lucent {
namespace {

// CacheWriteScope depth in this thread: cache entries commit at once and may replace what the run
// read (a corrupt entry read, refused and rebuilt is lucent's own file, not a user's input).
thread_local int cache_writes = 0;

struct Deferred {
  fs::path temporary, target;
  bool folder = false;
};

struct Registry {
  std::mutex mutex;
  std::set<fs::path> temporaries;     // live, removed on failure or signal
  std::set<fs::path> folders;         // the temporaries above that are folders
  std::vector<fs::path> inputs;       // weakly canonical
  std::vector<Deferred> deferred;     // renames waiting for the transaction
  std::set<fs::path> swept;           // folders already cleaned of dead processes' temporaries
  std::vector<std::string> warnings;  // for stderr once the transaction commits
  bool transaction = false;
  bool replace_folders = false;
};

Registry& registry() {
  static Registry* r = new Registry;  // never destroyed: the signal thread may use it at exit
  return *r;
}

// Distinguishes temporaries of one process; the pid distinguishes processes.
std::atomic<unsigned long> g_counter{0};

std::string temporary_suffix() {
  return ".tmp-" + std::to_string(static_cast<long>(::getpid())) + "-" +
         std::to_string(g_counter.fetch_add(1));
}

// "." + name + the temporary suffix + extra, the name cut so that the whole stays within a file
// name's 255 bytes (a legal 249-byte output was refused: its temporary's name was too long).
std::string temporary_name(const std::string& name, const std::string& extra = "") {
  const std::string suffix = temporary_suffix();
  constexpr std::size_t kNameMax = 255;
  const std::size_t room = kNameMax - 1 - suffix.size() - extra.size();
  return "." + (name.size() > room ? name.substr(0, room) : name) + suffix + extra;
}

fs::path canonical_or_self(const fs::path& p) {
  std::error_code ec;
  fs::path c = fs::weakly_canonical(p, ec);
  return ec ? fs::absolute(p, ec) : c;
}

fs::path folder_of(const fs::path& target) {
  fs::path parent = target.parent_path();
  return parent.empty() ? fs::path(".") : parent;
}

// `.NAME.tmp-PID-N` with an optional extension: lucent's temporaries, and only those.
const std::regex& temporary_pattern() {
  static const std::regex re(R"(^\..+\.tmp-([0-9]+)-[0-9]+(\.[A-Za-z0-9]+)*$)");
  return re;
}

// Removes, once per folder and process, the temporaries of processes that no longer exist (a run
// killed by SIGKILL or a power cut). A pid that is alive again (reused) keeps its files: removing
// too little is safe, removing another run's output is not.
void sweep_dead_temporaries(const fs::path& folder) {
  Registry& r = registry();
  {
    std::lock_guard lock(r.mutex);
    if (!r.swept.insert(canonical_or_self(folder)).second) return;
  }
  std::error_code ec;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    std::smatch m;
    if (!std::regex_match(name, m, temporary_pattern())) continue;
    const long pid = std::strtol(m[1].str().c_str(), nullptr, 10);
    if (pid <= 0 || pid == static_cast<long>(::getpid())) continue;
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;
    std::error_code ignored;
    fs::remove_all(it->path(), ignored);
  }
}

void track(const fs::path& temporary, bool folder) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  r.temporaries.insert(temporary);
  if (folder) r.folders.insert(temporary);
}

void untrack(const fs::path& temporary) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  r.temporaries.erase(temporary);
  r.folders.erase(temporary);
}

// Inside a temporary folder nothing is visible until the folder is renamed: no need to defer.
bool inside_temporary_folder(const fs::path& target, const Registry& r) {
  const fs::path t = canonical_or_self(target);
  for (const fs::path& f : r.folders) {
    const fs::path cf = canonical_or_self(f);
    auto [a, b] = std::mismatch(cf.begin(), cf.end(), t.begin(), t.end());
    if (a == cf.end()) return true;
  }
  return false;
}

bool is_within(const fs::path& path, const fs::path& folder) {
  auto [a, b] = std::mismatch(folder.begin(), folder.end(), path.begin(), path.end());
  return a == folder.end();
}

void check_not_an_input_locked(const fs::path& target, const Registry& r) {
  const fs::path t = canonical_or_self(target);
  for (const fs::path& in : r.inputs) {
    if (in == t) {
      throw Error(target.string() +
                  ": cannot write: it is an input of this run; choose another output name");
    }
  }
}

void check_folder_holds_no_input_locked(const fs::path& folder, const Registry& r) {
  const fs::path f = canonical_or_self(folder);
  for (const fs::path& in : r.inputs) {
    if (is_within(in, f)) {
      throw Error(folder.string() + ": cannot replace this folder: it holds " + in.string() +
                  ", an input of this run; choose another output folder");
    }
  }
}

// Renames now, or hands the rename to the open transaction.
void finish(const fs::path& temporary, const fs::path& target, bool folder) {
  Registry& r = registry();
  {
    std::lock_guard lock(r.mutex);
    if (cache_writes == 0) check_not_an_input_locked(target, r);
    if (r.transaction && !inside_temporary_folder(target, r) && cache_writes == 0) {
      r.deferred.push_back({temporary, target, folder});
      return;
    }
  }
  std::error_code ec;
  if (folder && fs::exists(target)) {
    const fs::path backup = folder_of(target) / temporary_name(target.filename().string(), ".old");
    fs::rename(target, backup, ec);
    if (!ec) {
      fs::rename(temporary, target, ec);
      if (ec) {
        std::error_code ignored;
        fs::rename(backup, target, ignored);
      } else {
        fs::remove_all(backup, ec);
        ec.clear();
      }
    }
  } else {
    fs::rename(temporary, target, ec);
  }
  if (ec) {
    throw Error(target.string() + ": cannot write: rename from " + temporary.string() +
                " failed: " + ec.message());
  }
  untrack(temporary);
}

// A number token that is not finite: nan, -nan, inf, +inf, infinity (any case), as text writers
// print them. Words that merely contain these letters ("info", "infinite") are not tokens, and
// comment lines ('#': names, units, provenance, from validated values) are not searched.
std::size_t find_non_finite_token(std::string_view text) {
  auto is_separator = [](char c) {
    return c == ',' || c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '=' || c == ':' ||
           c == '[' || c == ']';
  };
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && is_separator(text[i])) ++i;
    if (i < text.size() && text[i] == '#' && (i == 0 || text[i - 1] == '\n')) {
      const std::size_t eol = text.find('\n', i);
      i = eol == std::string_view::npos ? text.size() : eol + 1;
      continue;
    }
    std::size_t j = i;
    while (j < text.size() && !is_separator(text[j])) ++j;
    std::string token(text.substr(i, j - i));
    for (char& c : token) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (!token.empty() && (token[0] == '-' || token[0] == '+')) token.erase(0, 1);
    if (token == "nan" || token == "inf" || token == "infinity" || token == "nan(ind)")
      return i;
    i = j;
  }
  return std::string_view::npos;
}

[[noreturn]] void fail(const fs::path& target, const std::string& what, int err) {
  throw Error(target.string() + ": cannot write: " + what + ": " + std::strerror(err));
}

// Why `target` is not a file lucent may replace, or "". Outputs replace their target by renaming
// a temporary over it: over a device, a FIFO or a socket (as root, /dev/full) that would replace
// the node itself, and over /dev/stdout the system's link, so such targets are refused, as is any
// name directly in /dev or anywhere in /proc (devices and streams, not files). A link to a regular
// file is replaced by the file, its old target left as it was. The cache's own entries are lucent's
// and are replaced whatever they are.
std::string not_a_file(const fs::path& target) {
  std::error_code ec;
  const fs::path folder = fs::weakly_canonical(fs::absolute(folder_of(target), ec), ec);
  // /dev itself (its folders such as /dev/shm hold real files) and all of /proc (/dev/fd is there).
  if (!ec && (folder == "/dev" || is_within(folder, "/proc")))
    return "in " + folder.string() + " (devices and streams, not files)";
  const fs::file_status st = fs::status(target, ec);
  switch (st.type()) {
    case fs::file_type::character:
      return "a character device";
    case fs::file_type::block:
      return "a block device";
    case fs::file_type::fifo:
      return "a FIFO";
    case fs::file_type::socket:
      return "a socket";
    default:
      return "";
  }
}

void check_a_file(const fs::path& target, const std::string& who) {
  if (cache_writes > 0) return;
  if (const std::string why = not_a_file(target); !why.empty())
    throw Error((who == target.string() ? who + ": cannot write: it is "
                                        : who + ": '" + target.string() + "' is ") +
                why +
                ", not a file lucent can replace (it writes whole files and renames them "
                "into place; give a file name)");
}

}  // namespace

void note_input(const fs::path& path) {
  Registry& r = registry();
  const fs::path c = canonical_or_self(path);
  std::lock_guard lock(r.mutex);
  if (!r.transaction) return;  // outside a command run (library use) there is nothing to protect
  if (std::find(r.inputs.begin(), r.inputs.end(), c) == r.inputs.end()) r.inputs.push_back(c);
}

void check_not_an_input(const fs::path& target) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  check_not_an_input_locked(target, r);
}

void warn(const std::string& line) {
  Registry& r = registry();
  {
    std::lock_guard lock(r.mutex);
    if (r.transaction) {
      r.warnings.push_back(line);
      return;
    }
  }
  std::fprintf(stderr, "%s\n", printable(line).c_str());
}

void check_output_folder(const fs::path& path) {
  const fs::path folder = folder_of(path);
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) {
    throw Error(path.string() + ": cannot write: the folder " + folder.string() +
                " does not exist");
  }
}

void check_output_file(const fs::path& path, const std::string& extension,
                       const std::string& option) {
  std::error_code ec;
  const std::string name = path.filename().string();
  if (name.empty() || name == "." || name == ".." || fs::is_directory(path, ec)) {
    throw Error(option + ": '" + path.string() + "' is not a file name (expected a file" +
                (extension.empty() ? std::string() : " ending in " + extension) + ")");
  }
  check_a_file(path, option);
  if (!extension.empty()) {
    std::string ext = path.extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (ext != extension) {
      throw Error(option + ": '" + path.string() + "': expected a file ending in " + extension);
    }
  }
  check_output_folder(path);
}

void set_replace_folders(bool allow) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  r.replace_folders = allow;
}

void write_file_atomically(const fs::path& path, std::string_view content, bool binary) {
  if (!binary) {
    if (const std::size_t at = find_non_finite_token(content); at != std::string_view::npos) {
      const std::size_t line = 1 + std::count(content.begin(), content.begin() + at, '\n');
      throw Error(path.string() + ": cannot write: line " + std::to_string(line) +
                  " would hold a non-finite number (lucent writes only finite values)");
    }
  }
  if (cache_writes == 0) check_not_an_input(path);
  check_a_file(path, path.string());
  sweep_dead_temporaries(folder_of(path));
  const fs::path temporary =
      folder_of(path) / temporary_name(path.filename().string());

  // POSIX calls rather than std::ofstream: a stream only reports "failed", while the user needs the
  // reason (no such folder, permission denied, disk full). O_EXCL: never reuse someone else's file.
  track(temporary, false);
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) {
    const int err = errno;
    untrack(temporary);
    fail(path, err == ENOENT ? "the folder " + folder_of(path).string() + " does not exist"
                             : "cannot create a temporary file there",
         err);
  }
  auto discard = [&](const std::string& what, int err) {
    ::close(fd);
    ::unlink(temporary.c_str());
    untrack(temporary);
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
    untrack(temporary);
    fail(path, "close failed", err);
  }
  try {
    finish(temporary, path, false);
  } catch (...) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    untrack(temporary);
    throw;
  }
}

AtomicOutputPath::AtomicOutputPath(fs::path target) : target_(std::move(target)) {
  check_not_an_input(target_);
  check_a_file(target_, target_.string());
  const fs::path folder = folder_of(target_);
  if (!fs::is_directory(folder)) {
    throw Error(target_.string() + ": cannot write: the folder " + folder.string() +
                " does not exist");
  }
  sweep_dead_temporaries(folder);
  // A hidden name (leading '.') so that a crash leaves nothing that looks like a result; the
  // extension stays last so that writers choosing the format from the name still see it.
  temporary_ = target_.parent_path() /
               temporary_name(target_.stem().string(), target_.extension().string());
  track(temporary_, false);
}

AtomicOutputPath::~AtomicOutputPath() {
  if (committed_) return;
  std::error_code ignored;  // a destructor must not throw; there is nothing to remove if unwritten
  fs::remove(temporary_, ignored);
  untrack(temporary_);
}

void AtomicOutputPath::commit() {
  if (committed_) return;
  std::error_code ec;
  if (!fs::is_regular_file(temporary_, ec)) {
    throw Error(target_.string() + ": cannot write: the temporary file " + temporary_.string() +
                " was not written");
  }
  finish(temporary_, target_, false);
  committed_ = true;
}

AtomicOutputDir::AtomicOutputDir(fs::path target) : target_(std::move(target)) {
  if (target_.filename().empty()) target_ = target_.parent_path();  // "out/" names "out"
  check_a_file(target_, target_.string());
  const fs::path parent = folder_of(target_);
  if (!fs::is_directory(parent)) {
    throw Error(target_.string() + ": cannot write: the folder " + parent.string() +
                " does not exist");
  }
  if (fs::exists(target_) && !fs::is_directory(target_)) {
    throw Error(target_.string() + ": cannot write: exists and is not a folder");
  }
  {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    if (fs::is_directory(target_)) {
      check_folder_holds_no_input_locked(target_, r);
      if (!fs::is_empty(target_) && !r.replace_folders) {
        throw Error(target_.string() +
                    ": the output folder exists; pass --force to replace it whole (its files "
                    "would be removed), or choose another folder");
      }
    }
  }
  sweep_dead_temporaries(parent);
  temporary_ = parent / temporary_name(target_.filename().string());
  std::error_code ec;
  fs::create_directory(temporary_, ec);
  if (ec) throw Error(target_.string() + ": cannot write: " + ec.message());
  track(temporary_, true);
}

AtomicOutputDir::~AtomicOutputDir() {
  if (committed_) return;
  std::error_code ignored;
  fs::remove_all(temporary_, ignored);
  untrack(temporary_);
}

void AtomicOutputDir::commit() {
  if (committed_) return;
  {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    if (fs::is_directory(target_)) check_folder_holds_no_input_locked(target_, r);
  }
  finish(temporary_, target_, true);
  committed_ = true;
}

OutputTransaction::OutputTransaction() {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  if (r.transaction) throw std::logic_error("OutputTransaction: one is already open");
  r.transaction = true;
  r.deferred.clear();
  r.inputs.clear();
  r.warnings.clear();
}

OutputTransaction::~OutputTransaction() {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  for (const Deferred& d : r.deferred) {
    std::error_code ignored;
    fs::remove_all(d.temporary, ignored);
    r.temporaries.erase(d.temporary);
    r.folders.erase(d.temporary);
  }
  r.deferred.clear();
  r.inputs.clear();
  r.warnings.clear();  // a failed run says only its error
  r.transaction = false;
}

void OutputTransaction::commit() { commit_pending_outputs(); }

CacheWriteScope::CacheWriteScope() { ++cache_writes; }
CacheWriteScope::~CacheWriteScope() { --cache_writes; }

void commit_pending_outputs() {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  // Checked again here: an input read after an output was written is protected too.
  for (const Deferred& d : r.deferred) {
    check_not_an_input_locked(d.target, r);
    if (d.folder && fs::is_directory(d.target)) check_folder_holds_no_input_locked(d.target, r);
  }
  struct Done {
    fs::path target, backup;
  };
  std::vector<Done> done;
  auto roll_back = [&] {
    for (auto it = done.rbegin(); it != done.rend(); ++it) {
      std::error_code ignored;
      fs::remove_all(it->target, ignored);
      if (!it->backup.empty()) fs::rename(it->backup, it->target, ignored);
    }
  };
  for (const Deferred& d : r.deferred) {
    std::error_code ec;
    fs::path backup;
    if (fs::exists(fs::symlink_status(d.target))) {
      backup = folder_of(d.target) /
               temporary_name(d.target.filename().string(), ".old");
      fs::rename(d.target, backup, ec);
    }
    if (!ec) fs::rename(d.temporary, d.target, ec);
    if (ec) {
      if (!backup.empty() && !fs::exists(d.target)) {
        std::error_code ignored;
        fs::rename(backup, d.target, ignored);
      }
      roll_back();
      throw Error(d.target.string() + ": cannot write: rename from " + d.temporary.string() +
                  " failed: " + ec.message() + " (no output was written)");
    }
    done.push_back({d.target, backup});
  }
  for (const Done& d : done) {
    std::error_code ignored;
    if (!d.backup.empty()) fs::remove_all(d.backup, ignored);
  }
  for (const Deferred& d : r.deferred) {
    r.temporaries.erase(d.temporary);
    r.folders.erase(d.temporary);
  }
  r.deferred.clear();
  for (const std::string& w : r.warnings) std::fprintf(stderr, "%s\n", w.c_str());
  r.warnings.clear();
}

void remove_temporaries_on_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  std::thread([set] {
    int sig = 0;
    while (sigwait(&set, &sig) != 0) {
    }
    Registry& r = registry();
    // Waits for a commit in progress to finish, and stays locked: nothing new is created or
    // renamed into place before the process ends below.
    r.mutex.lock();
    for (const fs::path& t : r.temporaries) {
      std::error_code ignored;
      fs::remove_all(t, ignored);
    }
    ::signal(sig, SIG_DFL);
    sigset_t one;
    sigemptyset(&one);
    sigaddset(&one, sig);
    pthread_sigmask(SIG_UNBLOCK, &one, nullptr);
    ::raise(sig);
    ::_exit(128 + sig);  // not reached
  }).detach();
}

}  // namespace lucent
