// An interrupted command leaves nothing behind: SIGINT, SIGTERM and SIGHUP
// are taken by one watcher thread (sigwait), which removes every path still
// registered (temporaries, a directory the command made), newest first, and
// then ends the process by the same signal, so the shell sees how it ended.
#pragma once

#include <string>

namespace skinmesh::app {

// Call once at the start of main, before any other thread exists: the
// signals are blocked in every thread started later (TBB's workers too), so
// only the watcher receives them.
void watch_interrupts();

// A path removed if the process is interrupted while this lives. Files are
// unlinked; directories removed when empty (their files are registered too).
class RemovedOnInterrupt {
 public:
  explicit RemovedOnInterrupt(std::string path);
  ~RemovedOnInterrupt();
  RemovedOnInterrupt(RemovedOnInterrupt&& other) noexcept;
  RemovedOnInterrupt(const RemovedOnInterrupt&) = delete;
  RemovedOnInterrupt& operator=(const RemovedOnInterrupt&) = delete;
  RemovedOnInterrupt& operator=(RemovedOnInterrupt&& other) noexcept;

 private:
  void release();
  long id_ = -1;
};

}  // namespace skinmesh::app
