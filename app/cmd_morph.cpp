// skinmesh morph: the quality mesh of a source molecule carried frame by
// frame onto the skins of B(t) up to the target (morph/morph.hpp; the
// mathematics in docs/math.md section 4), every frame checked before anything
// is written, into a self-describing directory (docs/morph.md).
#include "commands.hpp"
#include "exit_codes.hpp"
#include "frame_options.hpp"
#include "meshing_feedback.hpp"
#include "morph_frames.hpp"
#include "molecule_options.hpp"
#include "output_file.hpp"
#include "quality_report.hpp"

#include "skinmesh/core/allocator.hpp"
#include "skinmesh/core/error.hpp"
#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/number_text.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_oracle.hpp"
#include "skinmesh/core/skin_topology.hpp"
#include "skinmesh/core/stopwatch.hpp"
#include "skinmesh/mesh_io/mesh_write.hpp"
#include "skinmesh/morph/alignment.hpp"
#include "skinmesh/morph/blend_topology.hpp"
#include "skinmesh/morph/matched_motion.hpp"
#include "skinmesh/morph/morph.hpp"
#include "skinmesh/morph/moving_balls.hpp"
#include "skinmesh/quality/mesh_quality.hpp"

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>

namespace skinmesh::app {
namespace {

using json = nlohmann::json;
namespace fs = std::filesystem;

struct MorphCommandOptions {
  MoleculeOptions molecule;  // settings shared by both sides (its --model is not used)
  std::string source, target, directory;
  int source_model = 1, target_model = 1;
  int frames = 21;
  std::vector<double> times;  // instead of --frames
  std::string align = "auto";
  std::string pairs = "auto";
  std::string spacing = "uniform";
  double max_step = MovingOptions{}.max_step;  // Angstrom, --pairs matched
  FrameFileOptions files;
  MorphOptions morph;
  FrameCrossingOptions crossings;
};

void add_morph_options(CLI::App& cmd, MorphCommandOptions& o) {
  cmd.add_option("source", o.source, "source molecule (any format a molecule is read from)")->required();
  cmd.add_option("target", o.target, "target molecule")->required();
  cmd.add_option("--output,-o", o.directory, "output directory (made if missing; one holding an earlier run's frames is refused)")
      ->required();
  cmd.add_option("--frames", o.frames, "frames at t = 0, 1/(N-1), ..., 1")
      ->check(finite_number())->check(CLI::Range(2, 100000))->capture_default_str();
  cmd.add_option("--t", o.times, "frame times in [0, 1] instead of --frames (comma-separated, increasing)")
      ->delimiter(',')->check(finite_number())->check(CLI::Range(0.0, 1.0));
  cmd.add_option("--source-model", o.source_model, "1-based model of the source file")
      ->check(finite_number())->check(positive_number());
  cmd.add_option("--target-model", o.target_model, "1-based model of the target file")
      ->check(finite_number())->check(positive_number());
  cmd.add_option("--align", o.align,
                 "auto (Kabsch on matched atoms when both sides are the same molecule, centroid otherwise), "
                 "none, centroid or kabsch")
      ->check(CLI::IsMember({"auto", "none", "centroid", "kabsch"}))->capture_default_str();
  cmd.add_option("--pairs", o.pairs,
                 "matched (each atom one ball that travels, radius kept), all (the m x n blend of every source "
                 "and target ball), or auto (matched when both sides are one molecule, as --align auto decides)")
      ->check(CLI::IsMember({"auto", "matched", "all"}))->capture_default_str();
  cmd.add_option("--spacing", o.spacing,
                 "with --frames: uniform (equal steps of t) or change (equal steps of the largest ball move: "
                 "centre plus skin radius)")
      ->check(CLI::IsMember({"uniform", "change"}))->capture_default_str();
  cmd.add_option("--max-step", o.max_step, "--pairs matched: largest move of an atom in one internal step, A")
      ->check(finite_number())->check(positive_number())->capture_default_str();
  cmd.add_option("--min-angle", o.morph.frames.min_angle, "smallest angle of every triangle of every frame, degrees")
      ->check(finite_number())->check(CLI::Range(1.0, 30.0))->capture_default_str();
  cmd.add_option("--epsilon", o.morph.first.sizing.epsilon, "curvature-relative size (edge / radius of curvature)")
      ->check(finite_number())->check(positive_number())->capture_default_str();
  cmd.add_option("--edge-length", o.morph.first.edge_length, "largest edge length in Angstrom (0: curvature only)")
      ->check(finite_number())->check(non_negative_number());
  cmd.add_option("--tolerance", o.morph.first.tolerance, "largest circumcentre distance from the skin, A")
      ->check(finite_number())->check(positive_number())->capture_default_str();
  cmd.add_option("--max-triangles", o.morph.first.max_triangles, "stop with an error past this many triangles")
      ->check(finite_number())->check(positive_number())->capture_default_str();
  cmd.add_option("--threads", o.morph.first.threads, "threads (0: all)")
      ->check(finite_number())->check(non_negative_number());
  add_frame_file_options(cmd, o.files);
  add_frame_crossing_options(cmd, o.crossings);
  add_molecule_settings(cmd, o.molecule, ModelChoice::none);
}

// The frame times asked for: increasing, in [0, 1].
std::vector<double> frame_times(const MorphCommandOptions& o) {
  std::vector<double> t = o.times;
  if (t.empty())
    for (int k = 0; k < o.frames; ++k) t.push_back(k == o.frames - 1 ? 1.0 : static_cast<double>(k) / (o.frames - 1));
  for (size_t k = 1; k < t.size(); ++k)
    if (!(t[k] > t[k - 1])) contract_error("--t: frame times must increase");
  if (t.back() == 0.0) contract_error("--t: at least one frame after t = 0 is needed");
  return t;
}

// The m x n blend's frames other than its ends keep this far from t = 0 and
// 1. Closer, the pair balls b_ij(t) of one ball lie within t |z_j - z_j'| of
// each other and the overlay complex of B(t) is degenerate to round-off:
// point location in it falls back to searching every cell, and a frame at
// 1e-6 took 3 to 22 times one at 1e-5, one at 1e-7 ran for minutes
// (docs/morph.md, limits).
constexpr double kBlendEndMargin = 1e-5;

void check_blend_times(const std::vector<double>& times) {
  for (double t : times) {
    if (!(t > 0 && t < 1 && std::min(t, 1 - t) < kBlendEndMargin * (1 - 1e-9))) continue;
    char text[32], margin[16];
    std::snprintf(text, sizeof text, "%.10g", t);
    std::snprintf(margin, sizeof margin, "%g", kBlendEndMargin);
    const std::string end = t < 0.5 ? "0" : "1";
    contract_error(std::string("frame time ") + text + " lies within " + margin + " of t = " + end +
                   ": there the m x n blend's balls of one atom differ by round-off and its complex cannot be "
                   "meshed in bounded time; use t = " + end + " itself or a time at least " + margin +
                   " from it; --pairs matched has no such limit");
  }
}

// The morph's frame criteria follow from the command's options: the first
// frame at the mesher's 30 degrees (room for transport), later frames at
// --min-angle, both with the sizing asked for.
MorphOptions morph_options(const MorphCommandOptions& o) {
  MorphOptions m = o.morph;
  m.shrink = o.molecule.shrink;
  const double angle = m.frames.min_angle;
  m.frames = m.first;
  m.frames.min_angle = angle;
  m.first.min_angle = std::max(30.0, angle);
  return m;
}

struct Sides {
  Molecule source, target;  // the target moved into the source's frame
  Alignment alignment;
  long unmoved = 0;  // target atoms put exactly on their source atom (snap_unmoved)
  std::vector<Ball> source_balls, target_balls;
};

Sides read_sides(const MorphCommandOptions& o) {
  Sides s;
  ReadOptions read = o.molecule.read;
  read.model = o.source_model;
  s.source = read_molecule(o.source, read);
  read.model = o.target_model;
  s.target = read_molecule(o.target, read);
  if (s.source.atoms.empty()) input_error(o.source, 0, "no atoms left to mesh");
  if (s.target.atoms.empty()) input_error(o.target, 0, "no atoms left to mesh");
  const std::map<std::string, AlignmentMethod> methods{{"auto", AlignmentMethod::automatic},
                                                       {"none", AlignmentMethod::none},
                                                       {"centroid", AlignmentMethod::centroid},
                                                       {"kabsch", AlignmentMethod::kabsch}};
  s.alignment = align(s.source, s.target, methods.at(o.align));
  s.target = moved(std::move(s.target), s.alignment.motion);
  s.unmoved = snap_unmoved(s.source, s.target);
  s.source_balls = balls_from_molecule(s.source, o.molecule.shrink, o.molecule.convention());
  s.target_balls = balls_from_molecule(s.target, o.molecule.shrink, o.molecule.convention());
  const auto empty = [](const std::vector<Ball>& balls) {
    return std::none_of(balls.begin(), balls.end(), [](const Ball& b) { return b.weight > 0; });
  };
  if (empty(s.source_balls)) input_error(o.source, 0, "the skin of this ball set is empty: no ball has a positive weight");
  if (empty(s.target_balls)) input_error(o.target, 0, "the skin of this ball set is empty: no ball has a positive weight");
  return s;
}

// What a frame is measured against: the morph oracle and, where it cannot
// certify, the complex of B(t)'s balls built from scratch.
struct FrameReference {
  const MorphOracle& oracle;
  const std::vector<BallPair>& pairs;  // the morph's live pairs, fixed for its whole run
  const std::vector<Ball>& source;
  const std::vector<Ball>& target;
  double shrink;
  // The balls of B(t) as a static set: the ends' own balls, the live pairs' in between.
  std::vector<Ball> balls_at(double t) const {
    if (t == 0.0) return source;
    if (t == 1.0) return target;
    return interpolated_balls(source, target, pairs, t);
  }
};

// The frame against the skin of B(t): distances by the morph oracle, which
// certifies every answer against all m x n pairs (a point it cannot certify
// is measured on the complex of B(t)'s balls built from scratch, a regular
// triangulation, not the morph's overlay); its solve at a vertex starts
// from the live pairs of the vertex's overlay cell (`starts`, indices into
// reference.pairs; empty: its own start). The topology from B(t)'s balls,
// or carried from an earlier frame's count when no critical point of the
// skin can lie between (blend_topology.hpp).
FrameCheck check_blend_frame(const SurfaceMesh& mesh, const std::vector<OracleStart>& starts,
                             const std::vector<long>& ids, const FrameReference& reference, double t,
                             double min_angle, FrameCheckHistory& history, CarriedTopology& topology) {
  SkinReference skin;
  skin.balls = reference.balls_at(t);
  skin.shrink = reference.shrink;
  const CountedTopology counted = topology.at(t, skin.balls);
  skin.topology = counted.topology;
  skin.starts = starts;
  skin.oracle = [&reference, t](const Eigen::Vector3d& x, const OracleStart& start) {
    std::vector<BallPair> pairs;
    for (int k : start)
      if (k >= 0 && k < static_cast<int>(reference.pairs.size())) pairs.push_back(reference.pairs[static_cast<size_t>(k)]);
    const MorphOracleResult e = reference.oracle.evaluate(x, t, pairs);
    return SkinDistance{e.distance(), e.certified};
  };
  FrameCheck check = check_frame(mesh, ids, skin, min_angle, history);
  check.topology_counted_at = counted.counted_at;
  return check;
}

// A frame of the blend copied out of the morph, with what writing it needs,
// so that it is checked and written while the next frame is made.
struct BlendFrame {
  size_t index = 0;
  double t = 0;
  MorphFrame frame;
  std::vector<int> patch;                 // per vertex: the dimension of its cell's Delaunay simplex
  std::vector<std::array<int, 2>> sides;  // per vertex: its source and target atoms (-1: none)
  std::vector<OracleStart> starts;        // per vertex in (0,1): its overlay cell's live pairs, where the check starts
};

BlendFrame snapshot_blend(const Morph& morph, size_t k, double t) {
  BlendFrame b;
  b.index = k;
  b.t = t;
  b.frame = morph.frame();
  for (int cell : b.frame.mesh.cells) b.patch.push_back(morph.complex().cell(cell).dim);
  b.sides = morph.vertex_atoms();
  // At t = 0 and 1 the frame lies on one side's own complex, whose balls are not pairs.
  if (t > 0 && t < 1)
    for (int cell : b.frame.mesh.cells) b.starts.push_back(morph.complex().cell(cell).balls);
  return b;
}

// The frame as `files` says, with per-vertex patch, id and the source and
// target atoms ("atom" and atomid: the source atom where there is one, the
// target atom otherwise).
void stage_frame(OutputSet& outputs, const OutputDirectory& dir, const BlendFrame& b, FrameFiles& files) {
  std::vector<int> atom;
  for (const auto& [s, t] : b.sides) atom.push_back(s >= 0 ? s : t);
  VertexAttributes a = frame_attributes(b.patch, std::move(atom), b.frame.ids, b.sides);
  stage_frame_files(outputs, dir, b.index, b.frame.mesh, a, b.sides, files);
}

json alignment_json(const Alignment& a, long unmoved) {
  json rotation = json::array();
  for (int r = 0; r < 3; ++r)
    rotation.push_back({a.motion.rotation(r, 0), a.motion.rotation(r, 1), a.motion.rotation(r, 2)});
  return {{"method", alignment_method_name(a.used)},
          {"matched_atoms", a.matched},
          {"rmsd", a.rmsd},
          {"rotation", rotation},
          {"translation", {a.motion.translation[0], a.motion.translation[1], a.motion.translation[2]}},
          {"maps", "target coordinates into the source's frame: x' = rotation x + translation"},
          {"unmoved_atoms", unmoved},
          {"unmoved_within", kUnmovedWithin},
          {"unmoved_means", "matched target atoms within unmoved_within A of their source atom after the motion, "
                            "put exactly on it"}};
}

// source.xyzr / target.xyzr (or .wpts when that side was read as weighted
// points): exactly the balls used, after alignment.
std::string stage_side(OutputSet& outputs, const OutputDirectory& dir, const std::string& side, const Molecule& m,
                       const std::vector<Ball>& balls) {
  const bool weighted = m.format == MoleculeFormat::Wpts;
  const std::string name = side + (weighted ? ".wpts" : ".xyzr");
  const std::string comment = side + " " + m.source + " (model " + std::to_string(m.model) + "), after alignment";
  outputs.add(dir.file(name), [&](std::ostream& out) {
    if (weighted) write_wpts(out, balls, comment);
    else write_xyzr(out, m, comment);
  });
  return name;
}

// The two sides as morph.json names them, either kind of morph.
json sides_json(const MorphCommandOptions& o, const Sides& sides) {
  return {{"source", o.source},
          {"target", o.target},
          {"source_model", o.source_model},
          {"target_model", o.target_model},
          {"source_atoms", sides.source_balls.size()},
          {"target_atoms", sides.target_balls.size()},
          {"shrink", o.molecule.shrink},
          {"weights", convention_name(o.molecule.convention())}};
}

// frames.pvd (with vtp), frames.glb (with glb), the atom tables; named in the report.
void stage_common_files(OutputSet& outputs, const OutputDirectory& dir, FrameFiles& files, const Sides& sides,
                        const std::vector<double>& times, json& report) {
  const bool pvd = files.wants("vtp");
  if (pvd) outputs.add(dir.file("frames.pvd"), [&](std::ostream& out) { write_pvd(out, times); });
  report["pvd"] = pvd ? json("frames.pvd") : json(nullptr);
  report["glb"] = files.wants("glb") ? json("frames.glb") : json(nullptr);
  report["colour"] = files.options.colour;
  report["atom_tables"] = {"source_atoms.tsv", "target_atoms.tsv"};
  stage_frame_set_files(outputs, dir, files, sides.source, sides.target);
}

json morph_json(const MorphCommandOptions& o, const Sides& sides, const Morph& morph, const std::vector<double>& t,
                const MorphOptions& options) {
  json events = json::array();
  for (const TopologyEvent& e : morph.events()) events.push_back({{"t", e.t}, {"cell", e.cell}, {"dim", e.dim}, {"euler_change", e.euler_change}});
  json j = sides_json(o, sides);
  j.update({{"ball_sets", "B(t) = {(1-t) a_i + t b_j}, weight (1-t) w_i + t w_j - t(1-t)|z_i - z_j|^2 "
                        "(docs/math.md section 4); live pairs " + std::to_string(morph.pairs().size())},
          {"alignment", alignment_json(sides.alignment, sides.unmoved)},
          {"frame_times", t},
          {"topology_events", events},
          {"min_angle", options.frames.min_angle},
          {"first_frame_min_angle", options.first.min_angle}});
  return j;
}

// Which balls the morph blends, and why (docs/morph.md, "Two kinds of morph").
struct Pairing {
  bool matched = false;
  std::string why;
};

Pairing choose_pairing(const MorphCommandOptions& o, const Sides& sides) {
  if (o.pairs == "matched") return {true, "asked for (--pairs matched)"};
  if (o.pairs == "all") return {false, "asked for (--pairs all)"};
  if (same_molecule(sides.source, sides.target))
    return {true, "both sides are one molecule (90% of the smaller side's atoms match by chain, residue and name): "
                  "its atoms travel"};
  return {false, "the sides are different molecules (under 90% of the smaller side's atoms match): the m x n blend"};
}

std::string unmoved_text(long unmoved) {
  if (unmoved == 0) return "";
  std::ostringstream text;
  text << "; " << unmoved << " atoms within " << kUnmovedWithin << " A of their source atom put exactly on it";
  return text.str();
}

void print_alignment(const Sides& sides) {
  std::cerr << "skinmesh: alignment " << alignment_method_name(sides.alignment.used)
            << (sides.alignment.used == AlignmentMethod::kabsch
                    ? " on " + std::to_string(sides.alignment.matched) + " matched atoms, RMSD " +
                          std::to_string(sides.alignment.rmsd) + " A"
                    : std::string())
            << unmoved_text(sides.unmoved) << "\n";
}

MovingOptions moving_options(const MorphOptions& m) {
  MovingOptions o;
  o.shrink = m.shrink;
  o.first = m.first;
  o.frames = m.frames;
  o.relaxation = m.relaxation;
  return o;  // the first frame's size margin and the repair policy stay the moving engine's own (moving_balls.hpp)
}

// --pairs matched: the atoms travel (matched_motion.hpp), carried by the
// moving-balls engine; every frame's balls are written beside it.
ExitCode run_matched_morph(const MorphCommandOptions& o, const GlobalOptions& global, const Sides& sides,
                           const std::vector<double>& times, const Pairing& pairing, Clock::time_point start) {
  const bool progress = !global.quiet && !global.json;
  const MorphOptions options = morph_options(o);
  const MatchedMotion motion = match_motion(sides.source, sides.source_balls, sides.target, sides.target_balls);
  MovingFrames run;
  run.times = times;
  run.balls_of = [&](size_t k) { return motion.balls_at(times[k]); };
  for (const MatchedMotion::Track& track : motion.tracks) run.ball_atoms.push_back({track.source, track.target});
  run.options = moving_options(options);
  run.options.max_step = o.max_step;
  FrameFiles files(o.files, sides.source, sides.target);
  run.crossings = o.crossings;
  if (progress) run.progress = std::make_shared<ProgressLine>(true);
  OutputDirectory dir(o.directory);
  OutputSet outputs;
  std::ostringstream lines;
  const MovingFramesResult result = run_moving_frames(run, files, outputs, dir, lines);
  if (!result.holds) {
    if (run.progress) run.progress->finish();
    std::cerr << "skinmesh: error: frame " << result.failed_index << " (t = " << times[result.failed_index]
              << ") fails a guarantee; nothing written\n"
              << json_text(result.failed_frame) << "\n";
    return ExitCode::not_met;
  }
  json report = sides_json(o, sides);
  report.update({{"skinmesh_version", version_text()},
                 {"command_line", global.command_line},
                 {"pairs", "matched"},
                 {"pairs_because", pairing.why},
                 {"ball_sets",
                  "one ball per atom: matched atoms (chain, residue number, insertion code, residue and atom name) on "
                  "straight lines from source to target, radius linear between the sides' radii; an atom on one side "
                  "only grows out of (or shrinks into) the nearest matched atom of its side, radius linear from 0 "
                  "(docs/morph.md); frame_NNNN.wpts holds every frame's balls"},
                 {"matched_atoms", motion.matched},
                 {"source_only_atoms", motion.source_only},
                 {"target_only_atoms", motion.target_only},
                 {"alignment", alignment_json(sides.alignment, sides.unmoved)},
                 {"frame_times", times},
                 {"spacing", o.spacing},
                 {"min_angle", options.frames.min_angle},
                 {"first_frame_min_angle", options.first.min_angle},
                 {"max_step", run.options.max_step}});
  report["source_balls_file"] = stage_side(outputs, dir, "source", sides.source, sides.source_balls);
  report["target_balls_file"] = stage_side(outputs, dir, "target", sides.target, sides.target_balls);
  stage_common_files(outputs, dir, files, sides, times, report);
  result.counts.into(report);
  report["min_ids_kept"] = result.min_ids_kept;
  report["max_kept_move"] = result.max_kept_move;
  report["seconds"] = seconds_since(start);
  outputs.add(dir.file("frames.jsonl"), [&](std::ostream& out) { out << lines.str(); });
  outputs.add(dir.file("morph.json"), [&](std::ostream& out) { out << json_text(report) << "\n"; });
  outputs.commit();
  dir.keep();
  if (global.json) std::cout << json_text(report) << "\n";
  else if (!global.quiet)
    std::cout << o.directory << ": " << result.counts.text() << ", matched atoms (" << pairing.why << "), ids kept "
              << result.min_ids_kept * 100 << "% or more a frame, " << report["seconds"].get<double>() << " s\n";
  return ExitCode::ok;
}

// --spacing change: the change from t to t' is the largest move of a ball
// between the two ball sets, its centre's way plus the change of its skin
// radius sqrt(s w) (a bound on how far the union of the shrunk balls
// moves); summed over a fine grid of t, the frames are put at equal shares
// of the sum. The m x n blend, whose weights fall by t(1-t)|a_i - b_j|^2,
// then takes small steps near the end, where balls grow fast.
std::vector<double> change_spaced(size_t frames, const std::function<std::vector<Ball>(double)>& balls_at, double shrink) {
  const size_t grid = std::min<size_t>(40000, std::max<size_t>(8192, 64 * (frames - 1)));
  const auto radius = [shrink](const Ball& b) { return std::sqrt(shrink * std::max(b.weight, 0.0)); };
  std::vector<double> sum(grid + 1, 0.0);
  std::vector<Ball> before = balls_at(0.0);
  for (size_t g = 1; g <= grid; ++g) {
    const std::vector<Ball> now = balls_at(static_cast<double>(g) / static_cast<double>(grid));
    double largest = 0;
    for (size_t i = 0; i < now.size(); ++i)
      largest = std::max(largest, (now[i].center - before[i].center).norm() + std::abs(radius(now[i]) - radius(before[i])));
    sum[g] = sum[g - 1] + largest;
    before = now;
  }
  std::vector<double> t{0.0};
  size_t g = 0;
  for (size_t k = 1; k + 1 < frames; ++k) {
    const double share = sum[grid] * static_cast<double>(k) / static_cast<double>(frames - 1);
    while (g < grid && sum[g + 1] < share) ++g;
    const double within = sum[g + 1] > sum[g] ? (share - sum[g]) / (sum[g + 1] - sum[g]) : 0.0;
    t.push_back((static_cast<double>(g) + within) / static_cast<double>(grid));
  }
  t.push_back(1.0);
  for (size_t k = 1; k < t.size(); ++k)  // strictly increasing, as advance_to needs
    if (!(t[k] > t[k - 1])) t[k] = std::nextafter(t[k - 1], 2.0);
  return t;
}

// Where the blend's frames go, and what is said of them.
struct BlendOutputs {
  FrameFiles& files;
  OutputSet& outputs;
  const OutputDirectory& dir;
  ProgressLine& shown;
  std::ostream& lines;  // frames.jsonl
  FrameCounts& counts;
};

// Every frame of the blend made, checked and staged; frame k is checked and
// staged while frame k+1 is made (the morph's repairs are mostly serial).
// False, with the failing frame reported, when a frame fails a guarantee.
bool make_blend_frames(Morph& morph, const std::vector<double>& times, const FrameReference& reference,
                       double min_angle, const FrameCrossingOptions& crossing_options, const BlendOutputs& out) {
  PaceEstimate pace(times.size());
  BlendFrame pending;
  FrameCheck check;
  FrameCheckHistory history(crossing_options);
  std::optional<CarriedTopology> topology;  // made by the first frame's check, beside the engine's next frame
  tbb::task_group checking;  // after what its task reads: if advance_to throws, it waits before they go
  const auto finish = [&]() {
    checking.wait();
    const json line = frame_json(pending.frame.stats, check, out.files.listed_file(pending.index));
    if (!check.holds()) {
      out.shown.finish();
      std::cerr << "skinmesh: error: frame " << pending.index << " (t = " << pending.t
                << ") fails a guarantee; nothing written\n"
                << json_text(line) << "\n";
      return false;
    }
    out.lines << json_text(line, JsonLayout::one_line) << "\n";
    out.counts.add(line);
    pace.done_one();
    print_progress(out.shown, pace, times.size(), pending.frame.stats, out.counts.repairs);
    return true;
  };
  for (size_t k = 0; k < times.size(); ++k) {
    if (k > 0) morph.advance_to(times[k], k + 1 < times.size() ? times[k + 1] : -1);
    BlendFrame made = snapshot_blend(morph, k, times[k]);
    if (k > 0 && !finish()) return false;
    pending = std::move(made);
    checking.run([&] {  // the check, then the frame's files, beside the next frame
      if (!topology)
        topology.emplace(TopologyWindows(morph.middle_complex(), morph.sizes(), reference.source, reference.target,
                                         reference.pairs, reference.oracle));
      check = check_blend_frame(pending.frame.mesh, pending.starts, pending.frame.ids, reference, pending.t, min_angle,
                                history, *topology);
      if (check.holds()) stage_frame(out.outputs, out.dir, pending, out.files);
    });
  }
  return finish();
}

ExitCode run_morph_frames(const MorphCommandOptions& o, const GlobalOptions& global) {
  check_formats(o.files.formats);
  const bool progress = !global.quiet && !global.json;
  const auto start = Clock::now();
  std::vector<double> times = frame_times(o);
  if (o.spacing == "change" && !o.times.empty()) contract_error("--spacing change goes with --frames, not --t");
  const MorphOptions options = morph_options(o);
  const Sides sides = read_sides(o);
  const Pairing pairing = choose_pairing(o, sides);
  if (o.spacing == "change") {
    if (pairing.matched) {
      const MatchedMotion motion = match_motion(sides.source, sides.source_balls, sides.target, sides.target_balls);
      times = change_spaced(times.size(), [&](double t) { return motion.balls_at(t); }, o.molecule.shrink);
    } else {
      const std::vector<BallPair> live = live_pairs(sides.source_balls, sides.target_balls);
      times = change_spaced(
          times.size(), [&](double t) { return interpolated_balls(sides.source_balls, sides.target_balls, live, t); },
          o.molecule.shrink);
    }
  }
  if (progress) {
    for (const auto& [path, m] : {std::pair{o.source, &sides.source}, std::pair{o.target, &sides.target}})
      for (const std::string& w : m->warnings) std::cerr << "skinmesh: warning: " << w << "\n";
    print_alignment(sides);
    std::cerr << "skinmesh: pairs " << (pairing.matched ? "matched" : "all") << ": " << pairing.why << "\n";
  }
  if (pairing.matched) return run_matched_morph(o, global, sides, times, pairing, start);
  check_blend_times(times);
  FrameFiles files(o.files, sides.source, sides.target);
  OutputDirectory dir(o.directory);
  OutputSet outputs;
  const auto shown = std::make_shared<ProgressLine>(progress);
  shown->note("preparing the morph: the live pairs, the complex of B(1/2), its topology events, the first frame");
  MorphOptions prepared = options;
  if (progress) prepared.first.progress = meshing_progress_line(shown);
  const MorphOracle oracle(sides.source_balls, sides.target_balls, o.molecule.shrink);
  Morph morph = prepare_morph(sides.source_balls, sides.target_balls, times.front(), prepared);
  shown->finish();
  const FrameReference reference{oracle, morph.pairs(), sides.source_balls, sides.target_balls, o.molecule.shrink};
  std::ostringstream lines;
  FrameCounts counts;
  const BlendOutputs out{files, outputs, dir, *shown, lines, counts};
  if (!make_blend_frames(morph, times, reference, options.frames.min_angle, o.crossings, out))
    return ExitCode::not_met;
  shown->finish();
  json report = morph_json(o, sides, morph, times, options);
  report["skinmesh_version"] = version_text();
  report["command_line"] = global.command_line;
  report["pairs"] = "all";
  report["spacing"] = o.spacing;
  report["pairs_because"] = pairing.why;
  report["source_balls_file"] = stage_side(outputs, dir, "source", sides.source, sides.source_balls);
  report["target_balls_file"] = stage_side(outputs, dir, "target", sides.target, sides.target_balls);
  stage_common_files(outputs, dir, files, sides, times, report);
  counts.into(report);
  report["seconds"] = seconds_since(start);
  outputs.add(dir.file("frames.jsonl"), [&](std::ostream& out) { out << lines.str(); });
  outputs.add(dir.file("morph.json"), [&](std::ostream& out) { out << json_text(report) << "\n"; });
  outputs.commit();
  dir.keep();
  if (global.json) std::cout << json_text(report) << "\n";
  else if (!global.quiet)
    std::cout << o.directory << ": " << counts.text() << ", alignment " << alignment_method_name(sides.alignment.used) << ", "
              << morph.events().size() << " topology events, " << report["seconds"].get<double>() << " s\n";
  return ExitCode::ok;
}

// A frame the mesher refuses is answered as `mesh` answers: an empty skin
// is bad input (exit 2), a budget or another refusal a job refused (exit 3).
ExitCode run_morph(const MorphCommandOptions& o, const GlobalOptions& global) {
  keep_large_blocks_for_reuse();  // frame after frame, the same large lists
  try {
    return run_morph_frames(o, global);
  } catch (const MeshingFailed& e) {
    return refused_meshing(e, o.source + " -> " + o.target);
  }
}

}  // namespace

void add_morph_command(CLI::App& app, const GlobalOptions& global, int& exit_code) {
  add_command(app, "morph", "quality meshes of every frame of a morph from one molecule to another", global,
              exit_code, add_morph_options, run_morph);
}

}  // namespace skinmesh::app
