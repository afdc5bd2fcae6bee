// What the terminal shows while the mesher works and when it refuses a job:
// shared by `mesh` and `volume`.
#pragma once

#include "exit_codes.hpp"
#include "progress.hpp"

#include "skinmesh/mesher/skin_mesher.hpp"

#include <memory>

#include <string>

namespace skinmesh::app {

// The mesher's progress on `line`: stage, vertices, and (when the mesher
// has an estimate) the share done and the time left at the pace so far.
std::function<void(const MeshingProgress&)> meshing_progress_line(std::shared_ptr<ProgressLine> line);

// For a job over its budget: the command-line options that would fit it
// (from SkinMeshResult::fitting_sizes), or the general advice. A command with
// only --epsilon and --edge-length (volume) passes surface_sizes_only.
std::string over_budget_hint(const SkinMeshResult& result, bool surface_sizes_only = false);

// A mesh refused inside a longer job (a morph's frame), said on stderr with
// `what` (the inputs) and answered with the exit code `mesh` would give.
ExitCode refused_meshing(const MeshingFailed& failure, const std::string& what);

// Bytes of memory this process may still use: the smaller of the system's
// available memory (/proc/meminfo MemAvailable) and what its cgroup's limit
// leaves (memory.max - memory.current); 0 when neither can be read.
double available_memory_bytes();

// The memory limit for --max-memory GB: that many bytes, or when it is 0 the
// memory available now.
inline double memory_limit_bytes(double max_memory_gb) {
  return max_memory_gb > 0 ? max_memory_gb * 1e9 : available_memory_bytes();
}

}  // namespace skinmesh::app
