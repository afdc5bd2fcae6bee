// Wall-clock seconds for stage timings in reports and progress.
#pragma once

#include <chrono>

namespace skinmesh {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace skinmesh
