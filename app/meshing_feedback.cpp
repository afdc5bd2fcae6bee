#include "meshing_feedback.hpp"

#include "skinmesh/core/stopwatch.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <sys/resource.h>
#include <unistd.h>

namespace skinmesh::app {

std::function<void(const MeshingProgress&)> meshing_progress_line(std::shared_ptr<ProgressLine> line) {
  const auto start = Clock::now();
  return [start, line](const MeshingProgress& p) {
    const double elapsed = seconds_since(start);
    char text[160];
    if (p.expected_vertices > 0) {
      // Refinement inserts points at a roughly even pace; the estimate can be
      // short (docs/benchmarks.md), so past it the line says nothing about time.
      const double done = std::min(0.99, static_cast<double>(p.vertices) / p.expected_vertices);
      if (done < 0.99 && done > 0.02)
        std::snprintf(text, sizeof text, "%-9s %9ld vertices, %3.0f%%, about %.0f s left", p.stage, p.vertices,
                      100 * done, elapsed * (1 - done) / done);
      else
        std::snprintf(text, sizeof text, "%-9s %9ld vertices, %3.0f%%", p.stage, p.vertices, 100 * done);
    } else {
      std::snprintf(text, sizeof text, "%-9s %9ld vertices, %8ld pending", p.stage, p.vertices, p.pending);
    }
    line->update(text);
  };
}

ExitCode refused_meshing(const MeshingFailed& failure, const std::string& what) {
  std::fprintf(stderr, "\nskinmesh: error: %s: %s\n", what.c_str(), failure.what());
  if (failure.status == MeshingStatus::over_budget)
    std::fprintf(stderr, "skinmesh: raise --max-triangles, or ask for coarser sizes (--epsilon, --edge-length)\n");
  return failure.status == MeshingStatus::empty_skin ? ExitCode::bad_input : ExitCode::not_met;
}

namespace {

const char* flag_of(SizeOption option, bool surface_sizes_only) {
  switch (option) {
    case SizeOption::epsilon: return "--epsilon";
    case SizeOption::edge_length: return "--edge-length";
    case SizeOption::tolerance: return surface_sizes_only ? nullptr : "--tolerance";
    case SizeOption::max_size: return surface_sizes_only ? nullptr : "--max-size";
    case SizeOption::min_size: return surface_sizes_only ? nullptr : "--min-size";
  }
  return nullptr;
}

}  // namespace

std::string over_budget_hint(const SkinMeshResult& result, bool surface_sizes_only) {
  std::ostringstream text;
  if (result.fitting_shrink > 0) {
    text << "this would fit: --shrink " << result.fitting_shrink << " (or raise --max-triangles or --max-memory)";
    return text.str();
  }
  const char* between_fits = "";
  for (const FittingSize& fit : result.fitting_sizes) {
    std::ostringstream flags;
    bool usable = true;
    for (const SizeChange& change : fit.changes) {
      const char* flag = flag_of(change.option, surface_sizes_only);
      if (!flag) usable = false;
      else flags << (flags.tellp() > 0 ? " " : "") << flag << " " << change.value;
    }
    if (!usable) continue;  // the command cannot set one of these sizes
    text << between_fits << flags.str();
    between_fits = ", or ";
  }
  if (surface_sizes_only) {
    if (text.tellp() == 0) return "ask for larger triangles (--epsilon, --edge-length)";
    return "this would fit: " + text.str();
  }
  if (text.tellp() == 0)
    return "raise --max-triangles or ask for larger triangles (--epsilon, --edge-length, --tolerance, --max-size)";
  return "this would fit: " + text.str() + " (or raise --max-triangles or --max-memory)";
}

namespace {

// A number from the first line of a file; -1 when missing or not a number ("max").
double number_in(const char* path) {
  std::ifstream in(path);
  double value = -1;
  if (!(in >> value)) return -1;
  return value;
}

double meminfo_available() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  double kilobytes = -1;
  while (in >> key) {
    if (key == "MemAvailable:") {
      in >> kilobytes;
      return kilobytes * 1024;
    }
    in.ignore(1 << 12, '\n');
  }
  return -1;
}

}  // namespace

double available_memory_bytes() {
  double available = meminfo_available();
  const double limit = number_in("/sys/fs/cgroup/memory.max"), used = number_in("/sys/fs/cgroup/memory.current");
  if (limit > 0 && used >= 0) available = available > 0 ? std::min(available, limit - used) : limit - used;
  // An address-space limit (ulimit -v) binds the process's virtual size,
  // which is more than what it has touched: what is left of it.
  struct rlimit address_space {};
  if (::getrlimit(RLIMIT_AS, &address_space) == 0 && address_space.rlim_cur != RLIM_INFINITY) {
    long pages = 0;
    std::ifstream statm("/proc/self/statm");
    statm >> pages;
    const double left = static_cast<double>(address_space.rlim_cur) - static_cast<double>(pages) * ::sysconf(_SC_PAGESIZE);
    available = available > 0 ? std::min(available, left) : left;
  }
  return std::max(0.0, available);
}

}  // namespace skinmesh::app
