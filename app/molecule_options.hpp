// Command-line options every subcommand that reads a molecule shares.
#pragma once

#include "commands.hpp"

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/molecule.hpp"

#include <CLI/CLI.hpp>

#include <string>

namespace skinmesh::app {

struct MoleculeOptions {
  std::string path;
  ReadOptions read;
  bool all_models = false;
  double shrink = 0.5;
  std::string weights = "grow";  // grow: w = r^2/s; raw: w = r^2
  WeightConvention convention() const {
    return weights == "raw" ? WeightConvention::Raw : WeightConvention::GrowBySkin;
  }
};

// Which model options a command takes: --model and --all-models (info),
// --model alone (one molecule meshed), or none (morph, interpolate and
// trajectory name their models their own way).
enum class ModelChoice { one_or_all, one, none };

// Filters, radii and skin parameters (without the file itself).
inline void add_molecule_settings(CLI::App& cmd, MoleculeOptions& o, ModelChoice models = ModelChoice::one) {
  if (models != ModelChoice::none)
    cmd.add_option("--model", o.read.model, "1-based model to read from a multi-model file")->check(finite_number())->check(positive_number());
  if (models == ModelChoice::one_or_all)
    cmd.add_flag("--all-models", o.all_models, "take every model (a list of conformations)");
  cmd.add_option("--chain", o.read.chains, "keep only these chains (repeatable)");
  cmd.add_flag("--keep-hydrogens", o.read.keep_hydrogens, "keep hydrogen atoms (dropped by default)");
  cmd.add_flag("--keep-waters", o.read.keep_waters, "keep water molecules (dropped by default)");
  cmd.add_option("--unknown-radius", o.read.unknown_radius, "radius in Angstrom for elements without a Bondi radius")
      ->check(finite_number())->check(positive_number());
  cmd.add_flag("--strict-elements", o.read.strict_elements, "fail on elements without a Bondi radius");
  cmd.add_option("--shrink,-s", o.shrink, "shrink factor s in (0,1)")->check(finite_number())->check(CLI::Range(1e-6, 1.0 - 1e-6));
  cmd.add_option("--max-input-bytes", o.read.max_bytes,
                 "refuse molecule files of more text than this (gunzipped size included)")
      ->check(positive_number())
      ->capture_default_str();
  cmd.add_option("--weights", o.weights, "ball weights: grow (w = r^2/s, skin near the vdW surface) or raw (w = r^2)")
      ->check(CLI::IsMember({"grow", "raw"}));
}

// The molecule as the subcommand's positional argument, plus its settings.
inline void add_molecule_options(CLI::App& cmd, MoleculeOptions& o, ModelChoice models = ModelChoice::one) {
  cmd.add_option("molecule", o.path, "PDB, mmCIF (.cif), PQR, XYZR or weighted points (.wpts), optionally .gz")->required();
  add_molecule_settings(cmd, o, models);
}

}  // namespace skinmesh::app
