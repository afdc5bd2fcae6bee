// Running the skinmesh command from a test: its exit code and what it printed.
#pragma once

#include <catch2/catch.hpp>

#include <array>
#include <cstdio>
#include <string>
#include <sys/wait.h>

namespace skinmesh::test {

struct Run {
  int code;
  std::string output;  // stdout and stderr together
};

// Runs a shell command line, stdout and stderr together.
inline Run run_shell(const std::string& command) {
  FILE* pipe = popen(command.c_str(), "r");
  REQUIRE(pipe != nullptr);
  std::string output;
  std::array<char, 4096> buffer{};
  size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) output.append(buffer.data(), n);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

inline Run run(const std::string& args) { return run_shell(std::string(SKINMESH_BINARY) + " " + args + " 2>&1"); }

// As run(), under a limit of `cpu_seconds` of CPU time: a run that stalls is
// killed (SIGXCPU) and reports code -1.
inline Run run_within(int cpu_seconds, const std::string& args) {
  return run_shell("ulimit -t " + std::to_string(cpu_seconds) + "; exec " + std::string(SKINMESH_BINARY) + " " +
                   args + " 2>&1");
}

}  // namespace skinmesh::test
