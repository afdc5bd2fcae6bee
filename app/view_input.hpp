// What `view` and `render --movie` read: a mesh file, or a morph directory
// (frames.jsonl naming its frames and their t, the PLY frames beside it),
// and the atom tables beside them (OUT.atoms.tsv for OUT.ply;
// source_atoms.tsv and target_atoms.tsv in a morph directory).
#pragma once

#include <map>
#include <string>
#include <vector>

namespace skinmesh::app {

struct ViewFrame {
  double t = 0;
  std::string path;  // the PLY file (for a mesh input, the file as given)
};

struct ViewInput {
  bool morph = false;
  std::vector<ViewFrame> frames;             // one for a mesh
  std::map<std::string, std::string> atoms;  // side ("mesh", "source", "target") -> its table's path, when present
};

// The columns an atom table's header must hold (UTF-8, tab-separated).
extern const char* const kAtomColumns[8];

// Throws InputError naming the file: a directory without frames.jsonl, a
// line without t or file, a frame without its PLY file, an atom table whose
// header lacks a column.
ViewInput find_view_input(const std::string& path);

// The atom table's side names a morph directory or a mesh has, each with
// its file name: {"mesh", "OUT.atoms.tsv"} or {"source", ...}, {"target", ...}.
std::vector<std::pair<std::string, std::string>> atom_table_names(const std::string& path, bool morph);

// A vertex's atom on one side ("mesh", "source" or "target") from a PLY's
// vertex properties, or -1 where it has none: read by name (a mesh's atom or
// atomid; a frame's source_atom, target_atom), a negative value or an
// unsigned -1 meaning none, as does a has_source_atom or has_target_atom of 0.
long vertex_atom(const std::map<std::string, std::vector<double>>& properties, size_t vertex, const std::string& side);

}  // namespace skinmesh::app
