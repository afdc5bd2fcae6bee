// The exit codes of the skinmesh command, named once.
#pragma once

namespace skinmesh::app {

enum class ExitCode : int {
  ok = 0,
  failure = 1,    // an unexpected error (a bug, or the system refused something)
  bad_input = 2,  // bad input data or options: InputError, ContractError, a usage error
  not_met = 3,    // the job ran, but its result is refused: over budget, a guarantee not met, TetGen failed
};

inline int code(ExitCode e) { return static_cast<int>(e); }

}  // namespace skinmesh::app
