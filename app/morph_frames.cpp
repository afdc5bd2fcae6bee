#include "morph_frames.hpp"

#include "meshing_feedback.hpp"

#include "output_file.hpp"
#include "quality_report.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/number_text.hpp"
#include "skinmesh/core/skin_oracle.hpp"
#include "skinmesh/core/skin_topology.hpp"
#include "skinmesh/core/stopwatch.hpp"
#include "skinmesh/mesh_io/atom_table.hpp"
#include "skinmesh/mesh_io/glb_write.hpp"
#include "skinmesh/mesh_io/mesh_write.hpp"
#include "skinmesh/quality/mesh_quality.hpp"

#include <Eigen/Geometry>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace skinmesh::app {

namespace fs = std::filesystem;
using json = nlohmann::json;

OutputDirectory::OutputDirectory(const std::string& path) : path_(path) {
  std::error_code error;
  if (fs::exists(path_, error)) {
    if (!fs::is_directory(path_, error)) unusable_output(path, "exists and is not a directory");
    remove_stale_staging(path_);
    // Frames of an earlier run would be mixed with this run's (its extra
    // frames left behind): refused before any work.
    for (const auto& entry : fs::directory_iterator(path_, error)) {
      const std::string name = entry.path().filename().string();
      if (name.rfind("frame_", 0) == 0 || name == "frames.jsonl" || name == "frames.pvd" || name == "morph.json" ||
          name == "trajectory.json")
        unusable_output(path, "holds an earlier run's output (" + name +
                                  "); remove it or choose a directory without frames");
    }
  } else {
    made_ = fs::create_directory(path_, error);
    if (!made_) unusable_output(path, "cannot make the output directory (" + error.message() + ")");
    removed_on_interrupt_.emplace_back(path_.string());
  }
}

OutputDirectory::~OutputDirectory() {
  std::error_code error;
  if (made_ && !kept_ && fs::is_empty(path_, error)) fs::remove(path_, error);
}

void OutputDirectory::keep() {
  kept_ = true;
  removed_on_interrupt_.clear();
}

void FrameCounts::add(const nlohmann::json& line) {
  const auto flag = [&](const char* key) { return line.contains(key) && line[key].is_boolean() && line[key].get<bool>(); };
  ++frames;
  from_scratch += flag("full_rebuild");
  repaired += flag("repaired");
  remeshed += flag("remeshed");
  repairs += line.value("repairs", 0L);
}

std::string FrameCounts::text() const {
  return std::to_string(frames) + " frames (" + std::to_string(from_scratch) + " meshed from scratch, " +
         std::to_string(repaired) + " repaired, " + std::to_string(remeshed) + " remeshed whole)";
}

void FrameCounts::into(nlohmann::json& report) const {
  report["frames"] = frames;
  report["full_rebuilds"] = from_scratch;
  report["repaired_frames"] = repaired;
  report["remeshed_frames"] = remeshed;
  report["repairs"] = repairs;
}

void check_formats(const std::vector<std::string>& formats) {
  for (size_t i = 0; i < formats.size(); ++i)
    if (std::find(formats.begin(), formats.begin() + static_cast<long>(i), formats[i]) != formats.begin() + static_cast<long>(i))
      contract_error("--format names " + formats[i] + " twice");
}

std::string frame_name(size_t k, const std::string& format) {
  char name[64];
  std::snprintf(name, sizeof name, "frame_%04zu.%s", k, format.c_str());
  return name;
}

FrameFiles::FrameFiles(const FrameFileOptions& o, const Molecule& source, const Molecule& target)
    : options(o), colouring(colouring_from_name(o.colour)) {
  check_formats(o.formats);
  if (o.ascii && !wants("ply") && !wants("vtp"))
    contract_error("--ascii: only PLY and VTP frames have a text form to choose; add ply or vtp to --format");
  source_colours = atom_colours(colouring, source.atoms);
  target_colours = atom_colours(colouring, target.atoms);
}

bool FrameFiles::wants(const std::string& format) const {
  return std::find(options.formats.begin(), options.formats.end(), format) != options.formats.end();
}

std::string FrameFiles::listed_file(size_t k) const {
  for (const std::string& f : options.formats)
    if (f != "glb") return frame_name(k, f);
  return "frames.glb";
}

VertexAttributes frame_attributes(std::vector<int> patch, std::vector<int> atom, const std::vector<long>& ids,
                                  const std::vector<std::array<int, 2>>& sides) {
  VertexAttributes a;
  a.patch = std::move(patch);
  a.atom = std::move(atom);
  std::vector<int> id, atomid, source, has_source, target, has_target;
  for (size_t v = 0; v < sides.size(); ++v) {
    const auto [s, t] = sides[v];
    if (s < 0 && t < 0) contract_error("a frame vertex with neither a source nor a target atom");
    id.push_back(static_cast<int>(ids[v]));
    atomid.push_back(s >= 0 ? s : t);
    source.push_back(std::max(s, 0));
    has_source.push_back(s >= 0);
    target.push_back(std::max(t, 0));
    has_target.push_back(t >= 0);
  }
  a.more = {{"id", PropertyType::int32, id},
            {"atomid", PropertyType::uint32, atomid},
            {"source_atom", PropertyType::uint32, source},
            {"has_source_atom", PropertyType::uint8, has_source},
            {"target_atom", PropertyType::uint32, target},
            {"has_target_atom", PropertyType::uint8, has_target}};
  return a;
}

void stage_frame_files(OutputSet& outputs, const OutputDirectory& dir, size_t k, const SurfaceMesh& mesh,
                       VertexAttributes& attributes, const std::vector<std::array<int, 2>>& sides, FrameFiles& files) {
  std::vector<Rgb> by_atom;
  if (colours_by_atom(files.colouring))
    for (const auto& [s, t] : sides)
      by_atom.push_back(s >= 0 ? files.source_colours[static_cast<size_t>(s)] : files.target_colours[static_cast<size_t>(t)]);
  attributes.colours = vertex_colours(files.colouring, mesh, attributes.patch, by_atom);
  MeshWriteOptions write;
  write.ascii = files.options.ascii;
  for (const std::string& format : files.options.formats) {
    if (format == "glb") continue;
    const MeshFormat mf = mesh_format_from_path(frame_name(k, format));
    outputs.add(dir.file(frame_name(k, format)), [&](std::ostream& out) { write_mesh(out, mesh, mf, &attributes, write); });
  }
  if (files.wants("glb")) {
    std::string node = frame_name(k, "glb");
    node.resize(node.size() - 4);  // frame_0007
    files.glb.push_back(glb_frame(mesh, attributes.colours, node, static_cast<double>(k) * FrameFiles::glb_seconds_per_frame));
  }
}

void stage_frame_set_files(OutputSet& outputs, const OutputDirectory& dir, FrameFiles& files, const Molecule& source,
                           const Molecule& target) {
  if (files.wants("glb"))
    outputs.add(dir.file("frames.glb"), [&](std::ostream& out) { write_glb(out, files.glb); });
  outputs.add(dir.file("source_atoms.tsv"), [&](std::ostream& out) { write_atom_table(out, source); });
  outputs.add(dir.file("target_atoms.tsv"), [&](std::ostream& out) { write_atom_table(out, target); });
}

void write_pvd(std::ostream& out, const std::vector<double>& times) {
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  for (size_t k = 0; k < times.size(); ++k)
    out << "<DataSet timestep=\"" << exact_number_text(times[k]) << "\" file=\"" << frame_name(k, "vtp")
        << "\"/>\n";
  out << "</Collection>\n</VTKFile>\n";
}

double share_below(const SurfaceMesh& mesh, double bound_degrees) {
  long below = 0;
  for (const auto& t : mesh.triangles) {
    double smallest = 180;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& p = mesh.vertices[static_cast<size_t>(t[static_cast<size_t>(k)])];
      const Eigen::Vector3d u = mesh.vertices[static_cast<size_t>(t[static_cast<size_t>((k + 1) % 3)])] - p;
      const Eigen::Vector3d w = mesh.vertices[static_cast<size_t>(t[static_cast<size_t>((k + 2) % 3)])] - p;
      smallest = std::min(smallest, std::atan2(u.cross(w).norm(), u.dot(w)) * 180.0 / M_PI);
    }
    below += smallest < bound_degrees;
  }
  return mesh.triangles.empty() ? 0.0 : static_cast<double>(below) / static_cast<double>(mesh.triangles.size());
}

const std::vector<char>* FrameCheckHistory::changed(const SurfaceMesh& mesh, const std::vector<long>& ids) {
  if (options_.skip || options_.pairs != "changed") return nullptr;
  now_ = CertifiedTriangles(mesh, ids);
  if (certified_.empty()) return nullptr;
  changed_ = certified_.changed_in(now_);
  return &changed_;
}

void FrameCheckHistory::checked(const SurfaceMesh& mesh, const SkinReference& skin, GuaranteeReport& report) {
  answers_ = OracleAnswers{};
  if (!skin.oracle && report.distances.size() == mesh.vertices.size())
    answers_ = OracleAnswers{skin.balls, skin.shrink, mesh.vertices, std::move(report.distances)};
  report.distances.clear();
  if (options_.skip || options_.pairs != "changed") return;
  certified_ = report.all_hold() ? std::move(now_) : CertifiedTriangles();
  now_ = CertifiedTriangles();
}

FrameCheck check_frame(const SurfaceMesh& mesh, const std::vector<long>& ids, const SkinReference& skin,
                       double min_angle, FrameCheckHistory& history) {
  GuaranteeOptions o;
  o.min_angle = min_angle;
  o.on_skin_tolerance = kFrameOnSkinTolerance;
  o.self_intersections = history.skipped() ? SelfIntersectionCheck::skip : SelfIntersectionCheck::exact;
  o.changed_triangles = history.changed(mesh, ids);
  o.earlier = history.earlier_answers();
  o.report_distances = !skin.oracle;
  FrameCheck c;
  c.guarantees = check_guarantees(mesh, skin, o);
  // The grade's smallest angle clearly above the bound (its formula may
  // differ from share_below's in the last bits): no triangle is below.
  c.share_below_bound = c.guarantees.quality.min_angle > min_angle + 1e-9 ? 0.0 : share_below(mesh, min_angle);
  history.checked(mesh, skin, c.guarantees);
  return c;
}

json frame_json(const FrameStats& s, const FrameCheck& c, const std::string& file) {
  const MeshQuality& q = c.guarantees.quality;
  const SkinTopology skin = c.guarantees.skin.value_or(SkinTopology{});
  return {{"t", s.t},
          {"file", file},
          {"vertices", s.vertices},
          {"triangles", s.triangles},
          {"min_angle", q.min_angle},
          {"share_below_bound", c.share_below_bound},
          {"moved", s.moved},
          {"relocated", s.relocated},
          {"inserted", s.inserted},
          {"removed", s.removed},
          {"repairs", s.repairs},
          {"edits", {{"split", s.split}, {"flipped", s.flipped}, {"contracted", s.contracted}}},
          {"bad_triangles_after_transport", s.bad_triangles},
          {"events", s.events},
          {"necks", s.necks},
          {"births", s.births},
          {"surgeries_undone", s.surgeries_undone},
          {"density", s.density},
          {"thinned", s.thinned},
          {"repaired", s.repaired},
          {"full_rebuild", s.full_rebuild},
          {"remeshed", s.remeshed},
          {"remeshed_because", s.remeshed ? json(s.remeshed_because) : json(nullptr)},
          {"max_onsurf_error", c.guarantees.surface_error.max},
          {"oracle_uncertified", c.guarantees.surface_error.uncertified},
          {"oracle_answers_kept", c.guarantees.distances_kept},
          {"components", q.components},
          {"voids", q.cavities},
          {"euler", q.euler},
          {"skin_topology",
           {{"components", skin.components},
            {"voids", skin.voids},
            {"euler", skin.euler},
            {"counted_at_t", c.topology_counted_at >= 0 ? c.topology_counted_at : s.t}}},
          {"self_intersecting_pairs", q.self_intersections_checked ? json(q.self_intersecting_pairs) : json(nullptr)},
          {"self_intersection_triangles_tested",
           q.self_intersections_checked ? json(q.self_intersection_triangles_tested) : json(nullptr)},
          {"seconds", s.seconds},
          {"seconds_complex", s.seconds_complex},
          {"seconds_transport", s.seconds_transport},
          {"seconds_relax", s.seconds_relax},
          {"seconds_judge", s.seconds_judge},
          {"seconds_repair", s.seconds_repair},
          {"seconds_edits", s.seconds_edits},
          {"seconds_patch", s.seconds_patch},
          {"patch_attempts", s.patch_attempts}};
}

void print_progress(ProgressLine& line, const PaceEstimate& pace, size_t total, const FrameStats& s, long repairs) {
  char text[160];
  const double left = pace.seconds_left();
  std::snprintf(text, sizeof text, "frame %zu/%zu  t = %.4f  %ld vertices  %ld repairs  %.0f s left", pace.done(), total,
                s.t, s.vertices, repairs, std::max(left, 0.0));
  line.update(text, pace.done() == total);
}

namespace {

// A frame as made, copied out of the engine so that it can be checked and
// written while the engine makes the next one.
struct MadeFrame {
  size_t index = 0;
  MorphFrame frame;
  std::vector<Ball> balls;
  SkinTopology topology;  // of `balls`, as the engine counted it (skin_topology)
  std::vector<OracleStart> starts;  // per vertex: its cell's balls, where the check's oracle starts
  std::vector<int> owner, patch;  // per vertex: its ball, its patch type
  double shrink = 0.5;
};

MadeFrame snapshot(const MovingBalls& moving, size_t k) {
  MadeFrame m;
  m.index = k;
  m.frame = moving.frame();
  m.balls = moving.balls();
  m.topology = moving.topology();
  m.owner = moving.vertex_balls();
  for (int c : m.frame.mesh.cells) {
    m.patch.push_back(moving.complex().cell(c).dim);
    m.starts.push_back(moving.complex().cell(c).balls);
  }
  m.shrink = moving.complex().shrink();
  return m;
}

FrameCheck check_moving_frame(const MadeFrame& made, double min_angle, FrameCheckHistory& history) {
  return check_frame(made.frame.mesh, made.frame.ids,
                     SkinReference{made.balls, made.shrink, {}, made.starts, made.topology}, min_angle, history);
}

json moving_frame_json(const FrameStats& s, const FrameCheck& c, const std::string& file) {
  json j = frame_json(s, c, file);
  j["steps"] = s.steps;
  j["steps_built_ahead"] = s.built_ahead;
  j["reidentified"] = s.reidentified;
  j["settled"] = s.settled;
  j["carried"] = s.carried;
  j["ids_kept"] = s.ids_kept;
  j["max_kept_move"] = s.max_kept_move;
  return j;
}

// The frame's mesh as `files` says, with per vertex its patch type, id,
// owning ball ("atom": the line of the frame's .wpts) and that ball's
// source and target atoms; and its balls.
void stage_moving_frame(OutputSet& outputs, const OutputDirectory& dir, const MadeFrame& made, const MovingFrames& run,
                        FrameFiles& files) {
  const MorphFrame& f = made.frame;
  std::vector<std::array<int, 2>> sides;
  for (int ball : made.owner) sides.push_back(run.ball_atoms[static_cast<size_t>(ball)]);
  VertexAttributes a = frame_attributes(made.patch, made.owner, f.ids, sides);
  const size_t k = made.index;
  stage_frame_files(outputs, dir, k, f.mesh, a, sides, files);
  outputs.add(dir.file(frame_name(k, "wpts")), [&](std::ostream& out) {
    write_wpts(out, made.balls, "the balls of " + files.listed_file(k) + " (t = " + exact_number_text(f.stats.t) + ")");
  });
}

}  // namespace

// Frame k is checked and written while frame k+1 is made: the engine's
// repairs are mostly serial and the check (grading, the oracle at every
// vertex, the exact self-intersection test) and the staging of the frame's
// files run beside them, one frame's after the other's.
MovingFramesResult run_moving_frames(const MovingFrames& run, FrameFiles& files, OutputSet& outputs,
                                     const OutputDirectory& dir, std::ostream& lines) {
  MovingFramesResult result;
  MovingOptions options = run.options;
  if (run.progress) {
    run.progress->note("meshing the first frame");
    options.first.progress = meshing_progress_line(run.progress);
  }
  PaceEstimate pace(run.times.size());
  MovingBalls moving(run.balls_of(0), options, run.times.front());
  MadeFrame pending;
  FrameCheck check;
  FrameCheckHistory history(run.crossings);
  tbb::task_group checking;
  // Waits for the pending frame's check and files, then records its line; false when it failed.
  const auto finish = [&]() {
    checking.wait();
    const FrameStats& st = pending.frame.stats;
    const json line = moving_frame_json(st, check, files.listed_file(pending.index));
    if (!check.holds()) {
      result.failed_frame = line;
      result.failed_index = pending.index;
      return false;
    }
    lines << json_text(line, JsonLayout::one_line) << "\n";
    result.counts.add(line);
    if (pending.index > 0) {
      result.min_ids_kept = std::min(result.min_ids_kept, st.ids_kept);
      result.max_kept_move = std::max(result.max_kept_move, st.max_kept_move);
    }
    pace.done_one();
    if (run.progress) print_progress(*run.progress, pace, run.times.size(), st, result.counts.repairs);
    return true;
  };
  for (size_t k = 0; k < run.times.size(); ++k) {
    if (k > 0)  // told the frame after, whose first step's complex is built beside this frame's repair
      moving.advance_to(run.balls_of(k), run.times[k], k + 1 < run.times.size() ? run.balls_of(k + 1) : std::vector<Ball>{});
    MadeFrame made = snapshot(moving, k);
    if (k > 0 && !finish()) return result;
    pending = std::move(made);
    checking.run([&] {
      check = check_moving_frame(pending, run.options.frames.min_angle, history);
      if (check.holds()) stage_moving_frame(outputs, dir, pending, run, files);
    });
  }
  if (!finish()) return result;
  if (run.progress) run.progress->finish();
  result.holds = true;
  return result;
}

}  // namespace skinmesh::app
