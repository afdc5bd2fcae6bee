// One fuzz input read the way a user's file is: written to a file with the
// target's extension in a private folder, then read by the public reader.
// What a reader accepts goes on: a mesh is graded (the grader on what the
// readers accept), a molecule of at most 300 atoms gets its complex. A
// reader may refuse an input only with skinmesh::Error (InputError naming
// the file); any other exception, a crash, a hang or a sanitizer report is
// a finding. Used by the libFuzzer targets (fuzz_main.cpp) and by the
// regression test that replays every kept input (test_fuzz_inputs.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace skinmesh::fuzz {

enum class InputKind {
  molecule,  // read_molecule
  mesh,      // read_surface_mesh
  gmsh,      // read_gmsh_volume
  msms,      // .vert and .face: the input split at its first NUL byte
  tetgen,    // .node, .ele and .face: the input split at its first two NUL bytes
};

struct FuzzTarget {
  std::string name;       // fuzz_<name>, tests/fuzz/inputs/<name>/
  std::string extension;  // of the file the input is written to
  InputKind kind;
};

const std::vector<FuzzTarget>& fuzz_targets();
const FuzzTarget& fuzz_target(const std::string& name);  // throws std::out_of_range

// Reads one input; `folder` must exist and belong to this process.
void read_fuzz_input(const FuzzTarget& target, const uint8_t* data, size_t size, const std::string& folder);

}  // namespace skinmesh::fuzz
