// What the commands that write a directory of frames share (morph,
// trajectory): the directory, the frame files' names, the ParaView
// collection, progress, and the frame loop of moving balls
// (morph/moving_balls.hpp), each frame checked before anything is written.
#pragma once

#include "output_file.hpp"
#include "progress.hpp"

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/skin_topology.hpp"
#include "skinmesh/core/surface_mesh.hpp"
#include "skinmesh/morph/morph.hpp"
#include "skinmesh/morph/moving_balls.hpp"
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
// A VTK collection: ParaView opens it as an animation over t.
void write_pvd(std::ostream& out, const std::vector<double>& times);
// The share of the triangles whose smallest angle is under the bound (degrees).
double share_below(const SurfaceMesh& mesh, double bound_degrees);
// A frame done on `line`: frames done, t, vertices, repairs and the time
// left at the pace of the latest frames (`pace` has counted this one).
void print_progress(ProgressLine& line, const PaceEstimate& pace, size_t total, const FrameStats& s, long repairs);

// What is measured of every frame before it is written, either kind of morph.
struct FrameCheck {
  MeshQuality quality;
  SkinTopology skin;             // of the frame's balls, from their alpha complex: the frame must have it
  double max_error = 0;          // distance of the vertices to the frame's skin by an oracle, Angstrom
  long uncertified = 0;          // vertices the oracle could not certify (measured on a complex built from scratch)
  double share_below_bound = 0;  // of the triangles, those whose smallest angle is under the bound
  bool holds = false;
};
// Fills share_below_bound and holds from the rest: the angle bound, closed
// oriented manifold enclosing positive volume, no self-intersections (when
// checked), every vertex within 1e-8 A, and the skin's topology.
void judge_frame(FrameCheck& c, const SurfaceMesh& mesh, double min_angle, bool self_intersections);
// The frames.jsonl fields both kinds of morph write.
nlohmann::json frame_json(const FrameStats& s, const FrameCheck& c, const std::string& file);

// A run of moving balls to write: frame k holds balls_of(k), recorded at times[k].
struct MovingFrames {
  std::vector<double> times;
  std::function<std::vector<Ball>(size_t)> balls_of;
  // Per ball: its atom on the source side and on the target side (-1 where
  // that side lacks it), written per vertex as source_atom and target_atom.
  std::vector<std::array<int, 2>> ball_atoms;
  MovingOptions options;
  std::vector<std::string> formats;  // mesh formats per frame
  bool self_intersections = true;    // the exact check on every frame
  std::shared_ptr<ProgressLine> progress;  // null: none
};

// The frames as frames.jsonl describes them, counted from its lines, so that
// the terminal's summary, the report and the file agree.
struct FrameCounts {
  long frames = 0;
  long from_scratch = 0;  // `full_rebuild`: the first frame, and any later one meshed anew
  long repaired = 0;      // `repaired`
  long remeshed = 0;      // `remeshed` (moving atoms): remeshed whole from the frame's vertices
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
// `outputs` with its balls (frame_NNNN.wpts); `lines` gets frames.jsonl.
// Stops at the first frame that fails.
MovingFramesResult run_moving_frames(const MovingFrames& run, OutputSet& outputs, const OutputDirectory& dir,
                                     std::ostream& lines);

}  // namespace skinmesh::app
