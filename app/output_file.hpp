// Outputs are written to a temporary file beside the target and renamed into
// place, so a failure never leaves a partial file behind.
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace skinmesh::app {

// Calls write(stream) on PATH.tmp-XXXX, then renames it to PATH. Throws
// std::runtime_error (and removes the temporary) when anything fails.
void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace skinmesh::app
