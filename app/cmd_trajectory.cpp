// skinmesh trajectory: one continuous morph through the models of a
// multi-model file (an NMR ensemble, MD snapshots saved as models): each
// model a keyframe reached exactly, its atoms travelling on straight lines
// between keyframes, one mesh carried through the whole run with its vertex
// ids (morph/moving_balls.hpp; docs/morph.md, "Trajectories").
#include "commands.hpp"
#include "exit_codes.hpp"
#include "frame_options.hpp"
#include "molecule_options.hpp"
#include "meshing_feedback.hpp"
#include "morph_frames.hpp"
#include "output_file.hpp"
#include "quality_report.hpp"

#include "skinmesh/core/allocator.hpp"
#include "skinmesh/core/error.hpp"
#include "skinmesh/core/stopwatch.hpp"
#include "skinmesh/morph/alignment.hpp"
#include "skinmesh/morph/moving_balls.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <sstream>

namespace skinmesh::app {
namespace {

using json = nlohmann::json;

struct TrajectoryOptions {
  MoleculeOptions molecule;
  std::string directory;
  std::string models;        // "A-B" or "A,B,C" (1-based); empty: every model
  int every = 1;             // every K-th model of those
  int frames_per_step = 5;   // frames from one keyframe to the next (the next keyframe included)
  std::string align = "kabsch";
  MovingOptions moving;
  FrameFileOptions files;
  FrameCrossingOptions crossings;
};

void add_trajectory_options(CLI::App& cmd, TrajectoryOptions& o) {
  cmd.add_option("molecule", o.molecule.path, "multi-model PDB or mmCIF (optionally .gz)")->required();
  cmd.add_option("--output,-o", o.directory, "output directory (made if missing; one holding an earlier run's frames is refused)")->required();
  cmd.add_option("--models", o.models, "models to take, 1-based: a range A-B or a list A,B,C (default: all)");
  cmd.add_option("--every", o.every, "take every K-th of those models")
      ->check(finite_number())->check(CLI::Range(1, 1000000))->capture_default_str();
  cmd.add_option("--frames-per-step", o.frames_per_step, "frames from one model to the next (1: the models alone)")
      ->check(finite_number())->check(CLI::Range(1, 100000))->capture_default_str();
  cmd.add_option("--align", o.align, "kabsch (each model fitted onto the first on all its atoms) or none")
      ->check(CLI::IsMember({"none", "kabsch"}))->capture_default_str();
  cmd.add_option("--min-angle", o.moving.frames.min_angle, "smallest angle of every triangle of every later frame, degrees")
      ->check(finite_number())->check(CLI::Range(1.0, 30.0))->capture_default_str();
  cmd.add_option("--epsilon", o.moving.first.sizing.epsilon, "curvature-relative size (edge / radius of curvature)")
      ->check(finite_number())->check(positive_number())->capture_default_str();
  cmd.add_option("--edge-length", o.moving.first.edge_length, "largest edge length in Angstrom (0: curvature only)")
      ->check(finite_number())->check(non_negative_number())->capture_default_str();
  cmd.add_option("--tolerance", o.moving.first.tolerance, "largest circumcentre distance from the skin, A")
      ->check(finite_number())->check(positive_number())->capture_default_str();
  cmd.add_option("--max-step", o.moving.max_step, "largest move of an atom in one internal step, A")
      ->check(finite_number())->check(positive_number())->capture_default_str();
  cmd.add_option("--max-triangles", o.moving.first.max_triangles, "stop with an error past this many triangles")
      ->check(finite_number())->check(positive_number())->capture_default_str();
  add_frame_file_options(cmd, o.files);
  add_frame_crossing_options(cmd, o.crossings);
  add_molecule_settings(cmd, o.molecule, ModelChoice::none);
}

// The 1-based model numbers --models and --every select among `count`.
std::vector<int> selected_models(const TrajectoryOptions& o, int count) {
  std::vector<int> listed;
  if (o.models.empty()) {
    for (int m = 1; m <= count; ++m) listed.push_back(m);
  } else if (o.models.find('-') != std::string::npos) {
    int first = 0, last = 0;
    char dash = 0;
    std::istringstream in(o.models);
    if (!(in >> first >> dash >> last) || dash != '-' || !in.eof() || first < 1 || last < first)
      contract_error("--models: expected a range A-B of 1-based models, not '" + o.models + "'");
    for (int m = first; m <= last; ++m) listed.push_back(m);
  } else {
    std::istringstream in(o.models);
    std::string item;
    while (std::getline(in, item, ',')) {
      char* end = nullptr;
      const long m = std::strtol(item.c_str(), &end, 10);
      if (item.empty() || *end != '\0' || m < 1) contract_error("--models: '" + item + "' is no 1-based model number");
      listed.push_back(static_cast<int>(m));
    }
  }
  std::vector<int> out;
  for (size_t k = 0; k < listed.size(); k += static_cast<size_t>(o.every)) {
    if (listed[k] > count)
      contract_error("--models: model " + std::to_string(listed[k]) + " asked for, the file has " + std::to_string(count));
    out.push_back(listed[k]);
  }
  if (out.size() < 2) contract_error("a trajectory needs at least two models; " + std::to_string(out.size()) + " selected");
  return out;
}

// Per selected model, its balls in the first model's atom order, after the
// fit onto the first model. Every model must hold the first one's atoms.
std::vector<std::vector<Ball>> keyframe_balls(const TrajectoryOptions& o, const std::vector<Molecule>& all,
                                              const std::vector<int>& models, std::vector<double>& rmsd) {
  const Molecule& first = all[static_cast<size_t>(models.front() - 1)];
  std::vector<std::vector<Ball>> out;
  for (int m : models) {
    Molecule model = all[static_cast<size_t>(m - 1)];
    const auto pairs = matched_atoms(first, model);
    if (pairs.size() != first.atoms.size() || model.atoms.size() != first.atoms.size())
      input_error(o.molecule.path, 0,
                  "model " + std::to_string(m) + " does not hold the atoms of model " + std::to_string(models.front()) +
                      " (" + std::to_string(pairs.size()) + " of " + std::to_string(first.atoms.size()) +
                      " match by chain, residue and name; it has " + std::to_string(model.atoms.size()) + ")");
    const Alignment fit = align(first, model, o.align == "kabsch" ? AlignmentMethod::kabsch : AlignmentMethod::none);
    rmsd.push_back(fit.rmsd);
    model = moved(std::move(model), fit.motion);
    const std::vector<Ball> balls = balls_from_molecule(model, o.molecule.shrink, o.molecule.convention());
    std::vector<Ball> ordered(first.atoms.size());
    for (const auto& [i, j] : pairs) ordered[i] = balls[j];
    out.push_back(std::move(ordered));
  }
  return out;
}

ExitCode run_trajectory_frames(const TrajectoryOptions& o, const GlobalOptions& global) {
  check_formats(o.files.formats);
  const bool progress = !global.quiet && !global.json;
  const auto start = Clock::now();
  const std::vector<Molecule> all = read_all_models(o.molecule.path, o.molecule.read);
  const std::vector<int> models = selected_models(o, static_cast<int>(all.size()));
  std::vector<double> rmsd;
  const std::vector<std::vector<Ball>> keys = keyframe_balls(o, all, models, rmsd);
  const size_t per = static_cast<size_t>(o.frames_per_step);
  MovingFrames run;
  for (size_t k = 0; k <= (keys.size() - 1) * per; ++k)  // keyframe i at frame i * per, at time i
    run.times.push_back(static_cast<double>(k) / static_cast<double>(per));
  run.balls_of = [&](size_t k) {
    const size_t i = k / per, j = k % per;
    if (j == 0) return keys[i];
    const double a = static_cast<double>(j) / static_cast<double>(per);
    std::vector<Ball> balls = keys[i];
    for (size_t b = 0; b < balls.size(); ++b) balls[b].center = (1 - a) * keys[i][b].center + a * keys[i + 1][b].center;
    return balls;
  };
  for (size_t a = 0; a < keys.front().size(); ++a) run.ball_atoms.push_back({static_cast<int>(a), static_cast<int>(a)});
  run.options = o.moving;
  run.options.shrink = o.molecule.shrink;
  const double angle = run.options.frames.min_angle;
  run.options.frames = run.options.first;
  run.options.frames.min_angle = angle;
  run.options.first.min_angle = std::max(30.0, angle);
  // Every model holds the first one's atoms, and the balls are in its
  // order: both sides' atoms are the first model's (one table, twice).
  const Molecule& first = all[static_cast<size_t>(models.front() - 1)];
  FrameFiles files(o.files, first, first);
  run.crossings = o.crossings;
  if (progress) run.progress = std::make_shared<ProgressLine>(true);
  if (progress)
    std::cerr << "skinmesh: " << models.size() << " models of " << all.size() << ", " << keys.front().size()
              << " atoms each, " << run.times.size() << " frames\n";
  OutputDirectory dir(o.directory);
  OutputSet outputs;
  std::ostringstream lines;
  const MovingFramesResult result = run_moving_frames(run, files, outputs, dir, lines);
  if (!result.holds) {
    if (run.progress) run.progress->finish();
    std::cerr << "skinmesh: error: frame " << result.failed_index << " fails a guarantee; nothing written\n"
              << json_text(result.failed_frame) << "\n";
    return ExitCode::not_met;
  }
  std::vector<size_t> keyframes;
  for (size_t i = 0; i < keys.size(); ++i) keyframes.push_back(i * per);
  json report = {{"skinmesh_version", version_text()},
                 {"command_line", global.command_line},
                 {"source", o.molecule.path},
                 {"models", models},
                 {"models_in_file", all.size()},
                 {"keyframes", keyframes},
                 {"frames_per_step", per},
                 {"atoms", keys.front().size()},
                 {"shrink", o.molecule.shrink},
                 {"weights", convention_name(o.molecule.convention())},
                 {"alignment", o.align},
                 {"alignment_rmsd", rmsd},
                 {"ball_sets", "one ball per atom of the first model, in its order; between two keyframes the centres "
                               "on straight lines, radii kept; frame_NNNN.wpts holds every frame's balls"},
                 {"frame_times", run.times},
                 {"min_angle", run.options.frames.min_angle},
                 {"first_frame_min_angle", run.options.first.min_angle},
                 {"max_step", run.options.max_step},
                 {"min_ids_kept", result.min_ids_kept},
                 {"max_kept_move", result.max_kept_move},
                 {"seconds", seconds_since(start)}};
  result.counts.into(report);
  const bool pvd = files.wants("vtp");
  if (pvd) outputs.add(dir.file("frames.pvd"), [&](std::ostream& out) { write_pvd(out, run.times); });
  report["pvd"] = pvd ? json("frames.pvd") : json(nullptr);
  report["glb"] = files.wants("glb") ? json("frames.glb") : json(nullptr);
  report["colour"] = files.options.colour;
  report["atom_tables"] = {"source_atoms.tsv", "target_atoms.tsv"};
  stage_frame_set_files(outputs, dir, files, first, first);
  outputs.add(dir.file("frames.jsonl"), [&](std::ostream& out) { out << lines.str(); });
  outputs.add(dir.file("trajectory.json"), [&](std::ostream& out) { out << json_text(report) << "\n"; });
  outputs.commit();
  dir.keep();
  if (global.json) std::cout << json_text(report) << "\n";
  else if (!global.quiet)
    std::cout << o.directory << ": " << result.counts.text() << " through " << models.size() << " models, ids kept "
              << result.min_ids_kept * 100
              << "% or more a frame, " << report["seconds"].get<double>() << " s\n";
  return ExitCode::ok;
}

// A frame the mesher refuses: as `mesh` answers it (refused_meshing).
ExitCode run_trajectory(const TrajectoryOptions& o, const GlobalOptions& global) {
  keep_large_blocks_for_reuse();  // frame after frame, the same large lists
  try {
    return run_trajectory_frames(o, global);
  } catch (const MeshingFailed& e) {
    return refused_meshing(e, o.molecule.path);
  }
}

}  // namespace

void add_trajectory_command(CLI::App& app, const GlobalOptions& global, int& exit_code) {
  add_command(app, "trajectory", "one continuous morph through the models of a multi-model file", global,
              exit_code, add_trajectory_options, run_trajectory);
}

}  // namespace skinmesh::app
