#include "output_file.hpp"

#include "skinmesh/core/error.hpp"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sys/stat.h>
#include <unistd.h>

namespace skinmesh::app {

namespace {

constexpr const char* kStagingPrefix = ".skinmesh-";  // .skinmesh-PID-N.tmp
constexpr const char* kStagingSuffix = ".tmp";

// A hidden, short name beside `path` for staging it: the target's own name
// may be as long as the file system allows.
std::string staging_name(const std::string& path) {
  static std::atomic<long> counter{0};
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  return (folder / (kStagingPrefix + std::to_string(::getpid()) + "-" + std::to_string(counter++) + kStagingSuffix))
      .string();
}

}  // namespace

void remove_stale_staging(const std::filesystem::path& folder) {
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(folder.empty() ? "." : folder, error)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(kStagingPrefix, 0) != 0 || name.size() < 16 ||
        name.compare(name.size() - 4, 4, kStagingSuffix) != 0)
      continue;
    const long pid = std::strtol(name.c_str() + std::strlen(kStagingPrefix), nullptr, 10);
    if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) std::filesystem::remove(entry.path(), error);
  }
}

void unusable_output(const std::string& path, const std::string& message) {
  throw UnusableOutput(path + ": " + message);
}

OutputSet::~OutputSet() {
  for (const Staged& s : staged_) std::remove(s.temporary.c_str());
}

void OutputSet::add(const std::string& path, const std::function<void(std::ostream&)>& write) {
  const std::string temporary = staging_name(path);
  staged_.push_back({temporary, path, RemovedOnInterrupt(temporary)});  // removed by the destructor from here on
  std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
  if (!out) output_error(path, std::string("cannot write (") + std::strerror(errno) + ")");
  // A writer's own error (a stream that failed under it: a full disk, a
  // file size limit) is said with the file and the system's reason.
  errno = 0;
  try {
    write(out);
    out.flush();
  } catch (const OutputError& e) {
    output_error(path, std::string(e.what()) + (errno ? std::string(" (") + std::strerror(errno) + ")" : ""));
  }
  if (!out) output_error(path, std::string("write failed") + (errno ? std::string(" (") + std::strerror(errno) + ")" : ""));
}

void OutputSet::commit() {
  // An interrupt while the set is renamed removes what is in place so far.
  std::vector<RemovedOnInterrupt> placed;
  placed.reserve(staged_.size());
  while (!staged_.empty()) {
    const Staged& s = staged_.front();
    placed.emplace_back(s.target);
    if (std::rename(s.temporary.c_str(), s.target.c_str()) != 0)
      output_error(s.target, std::string("cannot rename into place (") + std::strerror(errno) + ")");
    staged_.erase(staged_.begin());
  }
}

void check_writable(const std::vector<std::string>& paths) {
  // Two outputs named alike would be written one over the other, and the
  // second rename would fail after the first: refused before any work.
  std::map<std::filesystem::path, std::string> seen;
  for (const std::string& path : paths) {
    std::error_code error;
    std::filesystem::path key = std::filesystem::weakly_canonical(std::filesystem::absolute(path), error);
    if (error) key = std::filesystem::absolute(path).lexically_normal();
    const auto [at, fresh] = seen.emplace(key, path);
    if (!fresh) unusable_output(path, "is named for two outputs (as " + at->second + " and as " + path + ")");
  }
  for (const std::string& path : paths) {
    struct stat info {};
    const bool found = ::stat(path.c_str(), &info) == 0;
    if (found && S_ISDIR(info.st_mode)) unusable_output(path, "is a directory");
    // The staging file's short name could be written; the rename would fail after the work.
    if (!found && errno == ENAMETOOLONG) unusable_output(path, "is a longer name than the file system allows");
    remove_stale_staging(std::filesystem::path(path).parent_path());
    const std::string probe = staging_name(path);
    std::ofstream out(probe, std::ios::binary | std::ios::trunc);
    if (!out) unusable_output(path, std::string("cannot write (") + std::strerror(errno) + ")");
    out.close();
    std::remove(probe.c_str());
  }
}

void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  OutputSet set;
  set.add(path, write);
  set.commit();
}

}  // namespace skinmesh::app
