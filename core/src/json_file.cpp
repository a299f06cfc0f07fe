// read_input_file, parse_json, read_json_file: see json_file.h.
#include "lucent/core/json_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <set>
#include <vector>

#include "lucent/core/atomic_file.h"

namespace lucent {

std::string read_input_file(const std::filesystem::path& path, std::size_t max_bytes) {
  const std::string source = path.string();
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw Error(source + ": cannot open: " + std::strerror(EISDIR));
  }
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw Error(source + ": cannot open: " + std::strerror(errno));
  // A regular file is judged by its size before a byte is read (a pipe or a device, by what it
  // gives, below).
  struct stat st {};
  if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && std::uint64_t(st.st_size) > max_bytes) {
    ::close(fd);
    throw Error(source + ": larger than " + std::to_string(max_bytes >> 20) +
                " MiB; not a file lucent reads (is it the right file?)");
  }
  note_input(path);
  std::string text;
  char chunk[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, chunk, sizeof chunk);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      throw Error(source + ": cannot read: " + std::strerror(err));
    }
    if (n == 0) break;
    if (text.size() + static_cast<std::size_t>(n) > max_bytes) {
      ::close(fd);
      throw Error(source + ": larger than " + std::to_string(max_bytes >> 20) +
                  " MiB; not a file lucent reads (is it the right file?)");
    }
    text.append(chunk, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return text;
}

namespace {

// nlohmann's messages start with an id ("[json.exception.parse_error.101] ") that means nothing to
// a user; the position after it does. Newlines would break the one-line rule.
std::string user_message(const std::exception& e) {
  std::string what = e.what();
  if (const auto end = what.find("] "); !what.empty() && what[0] == '[' && end != std::string::npos)
    what.erase(0, end + 2);
  for (char& ch : what) {
    if (ch == '\n' || ch == '\r') ch = ' ';
  }
  return what;
}

}  // namespace

nlohmann::json parse_json(std::string_view text, const std::string& source) {
  // The parser calls back with each object's keys one level below the object's own depth; one set
  // of keys per open object finds duplicates, which nlohmann would silently resolve to the last.
  // keys[L]: the keys seen so far of the open object whose keys come at level L; last_key[L]: the
  // latest of them (it names the object that starts below it); where[L]: that object's name.
  std::vector<std::set<std::string>> keys(2);
  std::vector<std::string> last_key(2), where(2, "the top level");
  auto grow = [&](std::size_t level) {
    if (keys.size() <= level) {
      keys.resize(level + 1);
      last_key.resize(level + 1);
      where.resize(level + 1);
    }
  };
  auto callback = [&](int depth, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    using E = nlohmann::json::parse_event_t;
    if (event == E::object_start || event == E::array_start) {
      if (depth >= kMaxJsonDepth) {
        throw Error(source + ": not valid JSON: nested deeper than " +
                    std::to_string(kMaxJsonDepth) + " levels");
      }
      if (event == E::object_start) {
        const std::size_t level = static_cast<std::size_t>(depth) + 1;
        grow(level);
        keys[level].clear();
        where[level] = depth == 0 ? std::string("the top level")
                                  : "object \"" + last_key[level - 1] + "\"";
      }
    } else if (event == E::key) {
      const std::size_t level = static_cast<std::size_t>(depth);
      grow(level);
      const std::string key = parsed.get<std::string>();
      if (!keys[level].insert(key).second) {
        throw Error(source + ": duplicate key \"" + key + "\" in " + where[level] +
                    " (which one is meant?)");
      }
      last_key[level] = key;
    }
    return true;
  };
  try {
    return nlohmann::json::parse(text.begin(), text.end(), callback);
  } catch (const nlohmann::json::exception& e) {
    throw Error(source + ": not valid JSON: " + user_message(e));
  }
}

nlohmann::json read_json_file(const std::filesystem::path& path) {
  return parse_json(read_input_file(path), path.string());
}

}  // namespace lucent
