// A morph's two sides as the benchmarks take them: "FILE[#MODEL]:FILE[#MODEL]"
// ("file#1:#3": two models of one file), read with the default filters,
// the target aligned as the command's `--align auto` does (and unmoved atoms
// put exactly on their source atoms, morph/alignment.hpp).
#pragma once

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/molecule.hpp"
#include "skinmesh/morph/alignment.hpp"

#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

namespace skinmesh::bench {

struct Pair {
  std::string name;
  std::vector<Ball> source, target;
  std::string alignment;
  std::string command_sides;  // the same sides as `skinmesh morph` arguments: files and model options
};

// "FILE#MODEL" as the file and the model (0: the reader's default).
struct Side {
  std::string file;
  int model = 0;
};
inline Side split_side(const std::string& spec) {
  const auto hash = spec.find('#');
  if (hash == std::string::npos) return {spec, 0};
  return {spec.substr(0, hash), std::atoi(spec.c_str() + hash + 1)};
}

inline Molecule read_side(const std::string& spec) {
  const Side side = split_side(spec);
  ReadOptions read;
  if (side.model > 0) read.model = side.model;
  return read_molecule(side.file, read);
}

inline Pair load_pair(const std::string& spec, double shrink) {
  const auto colon = spec.find(':');
  if (colon == std::string::npos) throw std::runtime_error("a pair is SOURCE:TARGET, got " + spec);
  std::string target_spec = spec.substr(colon + 1);
  const std::string source_spec = spec.substr(0, colon);
  if (!target_spec.empty() && target_spec[0] == '#')  // "file#1:#3": the same file
    target_spec = source_spec.substr(0, source_spec.find('#')) + target_spec;
  const Molecule source = read_side(source_spec);
  Molecule target = read_side(target_spec);
  const Alignment a = align(source, target, AlignmentMethod::automatic);
  target = moved(std::move(target), a.motion);
  snap_unmoved(source, target);
  Pair p;
  auto base = [](const std::string& s) { return s.substr(s.find_last_of('/') + 1); };
  p.name = base(source_spec) + " -> " + base(target_spec);
  p.source = balls_from_molecule(source, shrink);
  p.target = balls_from_molecule(target, shrink);
  p.alignment = alignment_method_name(a.used);
  const Side s = split_side(source_spec), t = split_side(target_spec);
  p.command_sides = "'" + s.file + "' '" + t.file + "'";
  if (s.model > 0) p.command_sides += " --source-model " + std::to_string(s.model);
  if (t.model > 0) p.command_sides += " --target-model " + std::to_string(t.model);
  return p;
}

}  // namespace skinmesh::bench
