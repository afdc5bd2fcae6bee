// What the commands that write a directory of frames share (morph,
// trajectory): the directory, the frame files' names, the ParaView
// collection, progress, and the frame loop of moving balls
// (morph/moving_balls.hpp), each frame checked before anything is written.
#pragma once

#include "output_file.hpp"
#include "progress.hpp"
#include "vertex_colours.hpp"

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/skin_topology.hpp"
#include "skinmesh/core/surface_mesh.hpp"
#include "skinmesh/mesh_io/glb_write.hpp"
#include "skinmesh/mesh_io/mesh_write.hpp"
#include "skinmesh/morph/morph.hpp"
#include "skinmesh/morph/moving_balls.hpp"
#include "skinmesh/quality/certified_triangles.hpp"
#include "skinmesh/quality/guarantees.hpp"
#include "skinmesh/quality/mesh_quality.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace skinmesh::app {

// The output directory: made when missing (and removed again when the
// command fails before anything is in it).
class OutputDirectory {
 public:
  explicit OutputDirectory(const std::string& path);
  ~OutputDirectory();
  OutputDirectory(const OutputDirectory&) = delete;
  OutputDirectory& operator=(const OutputDirectory&) = delete;
  void keep();
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
  bool made_ = false, kept_ = false;
  std::vector<RemovedOnInterrupt> removed_on_interrupt_;  // the directory, while made and not kept
};

std::string frame_name(size_t k, const std::string& format);  // frame_0007.ply
// --format's list: each format once (a frame written twice under one name
// would collide); throws ContractError naming the repeated one.
void check_formats(const std::vector<std::string>& formats);

// How the frames are written: the mesh formats (each frame its own file,
// but glb: every frame in one frames.glb), PLY as text, the colours.
struct FrameFileOptions {
  std::vector<std::string> formats{"ply", "vtp"};
  bool ascii = false;            // PLY and VTP as text (PyMOL 2.5 reads text PLY only)
  std::string colour = "patch";  // vertex_colours.hpp
};

// What the frames are written with, and what frames.glb collects.
struct FrameFiles {
  FrameFileOptions options;
  Colouring colouring = Colouring::patch;
  std::vector<Rgb> source_colours, target_colours;  // per atom of each side (colouring by atom)
  std::vector<GlbFrame> glb;                        // each frame so far, when glb is asked for
  static constexpr double glb_seconds_per_frame = 0.1;
  // Source and target atoms are indices into these (source_atoms.tsv,
  // target_atoms.tsv, written by stage_atom_tables).
  FrameFiles(const FrameFileOptions& o, const Molecule& source, const Molecule& target);
  bool wants(const std::string& format) const;
  std::string listed_file(size_t k) const;  // what frames.jsonl names: the first per-frame file, or frames.glb
};

// A frame's per-vertex properties: patch, atom (as the caller means it),
// id, and from each vertex's (source, target) atom pair, -1 for a side that
// lacks it: source_atom and target_atom (0 there) with has_source_atom and
// has_target_atom (0 or 1), and atomid, the source atom where there is one
// and the target atom otherwise. No atom column is negative; the atom
// columns and atomid are unsigned.
VertexAttributes frame_attributes(std::vector<int> patch, std::vector<int> atom, const std::vector<long>& ids,
                                  const std::vector<std::array<int, 2>>& sides);
// Frame k in every per-frame format, and kept for frames.glb; colours from `files`.
void stage_frame_files(OutputSet& outputs, const OutputDirectory& dir, size_t k, const SurfaceMesh& mesh,
                       VertexAttributes& attributes, const std::vector<std::array<int, 2>>& sides, FrameFiles& files);
// frames.glb (when asked for), source_atoms.tsv and target_atoms.tsv.
void stage_frame_set_files(OutputSet& outputs, const OutputDirectory& dir, FrameFiles& files, const Molecule& source,
                           const Molecule& target);
// A VTK collection: ParaView opens it as an animation over t.
void write_pvd(std::ostream& out, const std::vector<double>& times);
// The share of the triangles whose smallest angle is under the bound (degrees).
double share_below(const SurfaceMesh& mesh, double bound_degrees);
// A frame done on `line`: frames done, t, vertices, repairs and the time
// left at the pace of the latest frames (`pace` has counted this one).
void print_progress(ProgressLine& line, const PaceEstimate& pace, size_t total, const FrameStats& s, long repairs);

// What is measured of every frame before it is written, either kind of
// morph: the guarantees every mesh is checked for (check_guarantees), with
// the frame's skin, and the share of triangles under the angle bound.
struct FrameCheck {
  GuaranteeReport guarantees;
  double share_below_bound = 0;
  // The t of the frame whose balls' skin topology was counted (this frame's,
  // or an earlier one's carried: blend_topology.hpp); -1: this frame's.
  double topology_counted_at = -1;
  bool holds() const { return guarantees.all_hold(); }
};
// Every vertex of a frame within this of the frame's skin (Angstrom).
constexpr double kFrameOnSkinTolerance = 1e-8;

// Which pairs of a frame's triangles the exact self-intersection test
// looks at: none (skip), every pair ("all"), or ("changed") every pair of
// the first frame and then the pairs with a triangle that changed since
// the frame before (CertifiedTriangles: the others are where they were, by
// vertex id, and met only at shared corners then).
struct FrameCrossingOptions {
  bool skip = false;
  std::string pairs = "changed";
};
// The check's state through a run of frames, checked one after the other:
// the triangles the self-intersection test certified, and the static
// oracle's answers (OracleAnswers: a frame of moving atoms asks the oracle
// again only where a ball near a vertex moved, or the vertex did).
class FrameCheckHistory {
 public:
  explicit FrameCheckHistory(FrameCrossingOptions o = {}) : options_(std::move(o)) {}
  bool skipped() const { return options_.skip; }
  // Per triangle of `mesh` (ids per vertex), the triangles to test: null for all.
  const std::vector<char>* changed(const SurfaceMesh& mesh, const std::vector<long>& ids);
  // The answers of the frame before (null: none).
  const OracleAnswers* earlier_answers() const { return answers_.points.empty() ? nullptr : &answers_; }
  // After the frame's check: its triangles certified when every guarantee
  // held; its oracle answers kept when the static oracle gave them.
  void checked(const SurfaceMesh& mesh, const SkinReference& skin, GuaranteeReport& report);

 private:
  FrameCrossingOptions options_;
  CertifiedTriangles certified_, now_;
  std::vector<char> changed_;
  OracleAnswers answers_;
};

// The frame (ids per vertex) checked against `skin`: every guarantee, the
// topology included; `history` then holds this frame as the one before.
FrameCheck check_frame(const SurfaceMesh& mesh, const std::vector<long>& ids, const SkinReference& skin,
                       double min_angle, FrameCheckHistory& history);
// The frames.jsonl fields both kinds of morph write.
nlohmann::json frame_json(const FrameStats& s, const FrameCheck& c, const std::string& file);

// A run of moving balls to write: frame k holds balls_of(k), recorded at times[k].
struct MovingFrames {
  std::vector<double> times;
  std::function<std::vector<Ball>(size_t)> balls_of;
  // Per ball: its atom on the source side and on the target side (-1 where
  // that side lacks it), written per vertex as frame_attributes says.
  std::vector<std::array<int, 2>> ball_atoms;
  MovingOptions options;
  FrameCrossingOptions crossings;    // the exact self-intersection check of every frame
  std::shared_ptr<ProgressLine> progress;  // null: none
};

// The frames as frames.jsonl describes them, counted from its lines, so that
// the terminal's summary, the report and the file agree.
struct FrameCounts {
  long frames = 0;
  long from_scratch = 0;  // `full_rebuild`: the first frame, and any later one meshed anew
  long repaired = 0;      // `repaired`
  long remeshed = 0;      // `remeshed`: remeshed whole from the frame's vertices
  long repairs = 0;       // the sum of `repairs` (refinement insertions)
  void add(const nlohmann::json& line);
  std::string text() const;  // "21 frames (1 meshed from scratch, 18 repaired, 2 remeshed whole)"
  void into(nlohmann::json& report) const;  // frames, full_rebuilds, repaired_frames, remeshed_frames, repairs
};

struct MovingFramesResult {
  bool holds = false;           // every frame passed its checks (otherwise nothing is staged)
  nlohmann::json failed_frame;  // the frame that did not, as its frames.jsonl line
  size_t failed_index = 0;
  FrameCounts counts;
  double min_ids_kept = 1, max_kept_move = 0;  // over the frames after the first
};

// Every frame made, checked (the angle bound, closed oriented manifold
// without self-intersections, every vertex within 1e-8 A of the skin of the
// frame's balls by the static oracle, components, voids and Euler
// characteristic equal to skin_topology's of those balls) and staged into
// `outputs` as `files` says, with its balls (frame_NNNN.wpts); `lines` gets
// frames.jsonl. Stops at the first frame that fails.
MovingFramesResult run_moving_frames(const MovingFrames& run, FrameFiles& files, OutputSet& outputs,
                                     const OutputDirectory& dir, std::ostream& lines);

}  // namespace skinmesh::app
