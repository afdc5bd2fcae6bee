// Running the skinmesh command from a test: its exit code and what it printed.
#pragma once

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <array>
#include <cstdio>
#include <fstream>
#include <string>
#include <sys/wait.h>
#include <vector>

namespace skinmesh::test {

struct Run {
  int code;
  std::string output;  // stdout and stderr together
};

// The lines of a morph directory's frames.jsonl, one a frame.
inline std::vector<nlohmann::json> frame_lines(const std::string& dir) {
  std::ifstream in(dir + "/frames.jsonl");
  std::vector<nlohmann::json> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
  return lines;
}

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

// Whether this build runs under AddressSanitizer, which reserves terabytes
// of address space for its shadow memory: no address-space limit leaves it
// room to start.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kAddressSanitizer = true;
#else
inline constexpr bool kAddressSanitizer = false;
#endif
#else
inline constexpr bool kAddressSanitizer = false;
#endif

// How many times longer the command runs in this build: the sanitizers'
// build (scripts/sanitize.sh, -O1 with AddressSanitizer and
// UndefinedBehaviorSanitizer) ran the property test's morphs past 4 times
// their CPU time in the release build.
inline constexpr int kSlowdown = kAddressSanitizer ? 8 : 1;

// As run(), under a limit of `cpu_seconds` of CPU time (as the release build
// runs; kSlowdown times that here) and, when `memory_mb` is set, of that
// many MB of address space (not under AddressSanitizer: see above): a run
// that stalls is killed (SIGXCPU) and reports code -1; one that passes the
// memory limit fails an allocation.
inline Run run_within(int cpu_seconds, const std::string& args, long memory_mb = 0) {
  std::string limits = "ulimit -t " + std::to_string(cpu_seconds * kSlowdown) + "; ";
  if (memory_mb > 0 && !kAddressSanitizer) limits += "ulimit -v " + std::to_string(memory_mb * 1024) + "; ";
  return run_shell(limits + "exec " + std::string(SKINMESH_BINARY) + " " + args + " 2>&1");
}

}  // namespace skinmesh::test
