// A benchmark task in a forked child: its own peak memory, a time limit,
// and a crash or a timeout reported instead of taking the benchmark down.
#pragma once

#include "skinmesh/core/allocator.hpp"

#include <csignal>
#include <cstdio>
#include <exception>
#include <functional>
#include <string>
#include <sys/resource.h>
#include <sys/wait.h>
#include <type_traits>
#include <unistd.h>

namespace skinmesh::bench {

template <class Result>
struct Forked {
  std::string status = "ok";  // ok | timeout | failed
  Result result{};
  double peak_mb = 0;         // the child's peak resident memory
};

// Result goes back through a pipe as raw bytes, so it must be trivially copyable.
template <class Result>
Forked<Result> run_forked(int timeout_seconds, const std::function<Result()>& task) {
  static_assert(std::is_trivially_copyable_v<Result>);
  Forked<Result> out;
  int fds[2];
  if (pipe(fds) != 0) {
    out.status = "failed";
    return out;
  }
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    alarm(static_cast<unsigned>(timeout_seconds));
    return_large_blocks_to_system();  // as the skinmesh command does
    try {
      const Result r = task();
      if (write(fds[1], &r, sizeof r) != static_cast<ssize_t>(sizeof r)) _exit(1);
    } catch (const std::exception& error) {
      std::fprintf(stderr, "  failed: %s\n", error.what());
      _exit(2);
    }
    _exit(0);
  }
  close(fds[1]);
  const ssize_t got = read(fds[0], &out.result, sizeof out.result);
  close(fds[0]);
  int status = 0;
  struct rusage usage {};
  wait4(pid, &status, 0, &usage);
  out.peak_mb = usage.ru_maxrss / 1024.0;
  if (WIFSIGNALED(status) && WTERMSIG(status) == SIGALRM) out.status = "timeout";
  else if (got != static_cast<ssize_t>(sizeof out.result) || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
    out.status = "failed";
  return out;
}

}  // namespace skinmesh::bench
