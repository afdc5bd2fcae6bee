#include "output_file.hpp"

#include "skinmesh/core/error.hpp"

#include <cerrno>
#include <filesystem>
#include <map>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sys/stat.h>
#include <unistd.h>

namespace skinmesh::app {

void unusable_output(const std::string& path, const std::string& message) {
  throw UnusableOutput(path + ": " + message);
}

OutputSet::~OutputSet() {
  for (const Staged& s : staged_) std::remove(s.temporary.c_str());
}

void OutputSet::add(const std::string& path, const std::function<void(std::ostream&)>& write) {
  const std::string temporary = path + ".tmp-" + std::to_string(::getpid());
  staged_.push_back({temporary, path, RemovedOnInterrupt(temporary)});  // removed by the destructor from here on
  std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
  if (!out) output_error(path, std::string("cannot write (") + std::strerror(errno) + ")");
  write(out);
  out.flush();
  if (!out) output_error(path, "write failed");
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
    if (::stat(path.c_str(), &info) == 0 && S_ISDIR(info.st_mode)) unusable_output(path, "is a directory");
    const std::string probe = path + ".tmp-" + std::to_string(::getpid());
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
