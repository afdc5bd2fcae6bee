// All outputs of one command are written together or not at all: each file
// goes to a temporary beside its target, and only when every one of them has
// been written are they renamed into place. A failure (or a command that
// ends before commit()) leaves no file behind, nor does an interrupt
// (interrupt.hpp), during commit() included.
#pragma once

#include "interrupt.hpp"

#include "skinmesh/core/error.hpp"

#include <filesystem>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace skinmesh::app {

// An output named on the command line that cannot be used (a path that
// cannot be written, a directory holding an earlier run's frames), found
// before any work: a bad option (exit 2). An OutputError while writing is
// the system refusing (exit 1).
class UnusableOutput : public OutputError {
 public:
  using OutputError::OutputError;
};
[[noreturn]] void unusable_output(const std::string& path, const std::string& message);

class OutputSet {
 public:
  OutputSet() = default;
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;
  ~OutputSet();  // removes the temporaries not committed

  // Writes a hidden staging file beside PATH (.skinmesh-PID-N.tmp) now by
  // calling write(stream). Throws OutputError.
  void add(const std::string& path, const std::function<void(std::ostream&)>& write);
  // Renames every temporary into place. Throws OutputError when one cannot
  // be, after removing the temporaries left.
  void commit();

 private:
  struct Staged {
    std::string temporary, target;
    RemovedOnInterrupt guard;  // of the temporary
  };
  std::vector<Staged> staged_;
};

// Checks, before any work, that each path can be written (and removes the
// staging files of killed runs beside it): not a directory,
// in a folder that exists and takes a new file. Throws UnusableOutput naming the
// first that cannot; leaves nothing behind.
void check_writable(const std::vector<std::string>& paths);

// Removes the staging files in `folder` that a run killed outright (SIGKILL,
// a power cut) left: those whose process is gone. Others' are left alone.
void remove_stale_staging(const std::filesystem::path& folder);

// One output on its own: an OutputSet of one file, committed at once.
void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace skinmesh::app
