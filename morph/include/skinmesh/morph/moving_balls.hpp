// One molecule whose atoms move (docs/math.md section 6): the skin of a
// ball set whose centres (and, for atoms that appear or vanish, weights)
// change from call to call, its quality mesh carried along with vertex ids
// that mean a continuous motion. This is the engine of a matched morph
// (`skinmesh morph --pairs matched`), of `skinmesh trajectory` and of any
// caller that feeds coordinates frame by frame.
//
// The regular triangulation of moving balls changes combinatorially, so
// there is no fixed complex as in the m x n morph: every internal step
// builds the complex of its balls from scratch (exact predicates, CGAL) and
// a vertex keeps its mixed cell by the cell's ball tuple X
// (SkinComplex::find_cell). In a cell that persists, a vertex moves by the
// cell's exact map between its two quadrics: translate z_X, turn the
// direction space of delta_X onto its new place, scale by
// sqrt(R2_X(t1) / R2_X(t0)); where the cell is gone, turned flat or its
// size changed sign, the vertex is projected onto the new skin.
//
// Then every triangle is judged against the frame criteria; after a step
// that ended with every triangle passing, a triangle whose corners sit in
// skin this step left exactly as it was keeps that verdict unjudged
// (FrameStats::settled; docs/math.md section 6). Cheapest first, the
// failing triangles have their corners relaxed along the skin, are mended by edits (split, flip,
// contraction), then by a local patch; a frame whose topology changed or
// that still fails is remeshed whole from its vertices, and meshed from
// scratch only when that fails. Every step's mesh is certified: its
// components, voids and Euler characteristic must equal those of the skin
// of the step's balls counted from their weighted alpha complex
// (skin_topology.hpp), independently of the mesh; a step that cannot be
// certified throws Error.
#pragma once

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_topology.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/morph/morph.hpp"
#include "skinmesh/morph/relaxation.hpp"
#include "skinmesh/morph/repair_policy.hpp"

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace skinmesh {

class MovingBalls;

namespace detail {
struct VanishingSphere;  // vanishing.hpp (private to morph/)
// For tests only: `fault` is applied to every
// mesh of a step, with its ids, just before the topology certificate.
void inject_certificate_fault(MovingBalls& engine, std::function<void(SurfaceMesh&, std::vector<long>&)> fault);
}  // namespace detail

struct MovingOptions {
  double shrink = 0.5;    // s in (0,1)
  MeshingOptions first;   // the first frame's mesh (default: the mesher's 30 degrees)
  MeshingOptions frames = [] {  // every later frame is held to these criteria
    MeshingOptions o;
    o.min_angle = 20.0;   // degrees
    return o;
  }();
  // The first frame refined to `first` with its sizes times this
  // (dimensionless; below 1 denser). Later frames keep about the first
  // frame's density (repairs refine to `frames`, nothing thins), so at 1
  // they hold about as many triangles as a rebuild; the room to move is
  // the first frame's 30 degrees against the frames' 20.
  double first_size_margin = 1.0;
  // The largest move of a ball in one internal step (Angstrom): the centre's
  // move plus the change of its radius. A call moving balls farther is
  // split into equal steps. Fewer, longer steps cost less in all: each
  // step pays for the complex, the transport and the judging of the whole
  // mesh once, and its repairs grow less than its length
  // (docs/benchmarks.md, moving atoms).
  double max_step = 1.0;
  // A vertex keeps its id across a step when it moved at most the largest
  // move of its cell's balls plus this times its longest mesh edge; one
  // that moved farther (it jumped to another piece of skin) takes a new id.
  double continuity = 1.0;  // dimensionless
  // Each internal step's complex (and the skin's topology) is built beside
  // the repair of the step before, which is mostly serial, when the step's
  // balls are known then: the next step of a call, and a next call's first
  // step when advance_to is told its balls. The frames are the same.
  bool build_ahead = true;
  RelaxationOptions relaxation;  // for the corners of failing triangles
  // Every threshold of the repair (repair_policy.hpp): its defaults (the
  // blend's share of failing triangles is not taken) but for five of the
  // patch's. The largest patch: a third of the frame's
  // vertices (with the patch's context), not 0.9. Moving atoms fail
  // triangles in many places at once (thermal motion: all over the
  // surface), and a patch past a third of the frame cost more than
  // remeshing the frame whole, whether it succeeded or not
  // (docs/benchmarks.md, moving atoms). A patch's second
  // attempt meshes only around the first one's faults: bench_moving's 3mht
  // DNA motion (101 frames) spent 44% less time in local patches, its
  // frames 24% less in all; its hinge motion 3% less a frame. A patch that
  // fails is tried once more with one more ring (PatchPolicy::wider_rings)
  // before the step is remeshed whole. The local context reaches at most
  // six target lengths (PatchPolicy::local_reach_cap): on the hinge motion
  // the patches' contexts fell from 1,830 to 1,230 vertices an attempt on
  // average, with the same attempts and remeshes on all four motions. The
  // context reaches 1.5 times the local measure (PatchPolicy::context_reach):
  // the patches' triangles have largest angles near the 140 degrees a
  // 20-degree bound allows at most, and on the hinge motion the smaller
  // reach cut the context by 29% at the same remeshes. Necks are mended by
  // surgery (RepairPolicy::neck_surgery), and the edits reach eight
  // generations from a failing triangle, not three, as a neck's tube needs
  // more splits: with both, bench_moving's frames (101) took 9-11% less
  // time on 2k39 and on the DNA motion than with neither, 2-4% on the hinge.
  RepairPolicy repair = [] {
    RepairPolicy r;
    r.neck_surgery = true;
    r.edits.generations = 8;
    r.patch.max_sample_share = 0.3;  // a share, 0-1
    r.patch.retry_around_faults = true;
    r.patch.wider_rings = 1;
    r.patch.local_reach_cap = 6;  // target edge lengths
    r.patch.context_reach = 1.5;  // times the local measure
    return r;
  }();
};

class MovingBalls {
 public:
  // Meshes the skin of `balls`: the first frame (`t` in its stats).
  // Throws ContractError for an empty or non-finite ball set or options out
  // of range, Error when the mesher cannot mesh it.
  explicit MovingBalls(std::vector<Ball> balls, const MovingOptions& options = {}, double t = 0);

  // Moves every ball to its place in `balls` (the same balls in the same
  // order: ball i is the same atom), in internal steps of at most
  // options.max_step, and returns the frame. `t` is recorded in the frame's
  // stats. Throws ContractError for another number of balls or a
  // non-finite ball, Error when a step cannot be meshed or certified (the
  // engine then holds no valid frame and is not to be advanced again).
  const MorphFrame& advance_to(std::vector<Ball> balls, double t = 0);
  // The same, told the balls the next call will ask for (`next`, the same
  // number of balls): the complex of that call's first internal step is
  // built while this call's last step is mended, which is mostly serial
  // work, on the other core. A next call that asks for other balls builds
  // its own. The frames are the same either way; the call returns when
  // the building ahead is done, so that its frame's seconds hold it.
  const MorphFrame& advance_to(std::vector<Ball> balls, double t, std::vector<Ball> next);
  // The same with every ball's weight kept.
  const MorphFrame& advance_to(const std::vector<Eigen::Vector3d>& centres, double t = 0);

  const MorphFrame& frame() const;
  const SkinComplex& complex() const;
  const std::vector<Ball>& balls() const;
  const SkinTopology& topology() const;  // of balls(), which the frame's mesh has
  // Per vertex of the frame: the ball it belongs to (of its cell's balls,
  // the one of least power distance).
  std::vector<int> vertex_balls() const;

  // An engine moves; it is not copied.
  MovingBalls(MovingBalls&&) noexcept;
  MovingBalls& operator=(MovingBalls&&) noexcept;
  ~MovingBalls();

 private:
  struct Impl;  // moving_balls.cpp: the complex, the frame and the repair ladder
  std::unique_ptr<Impl> impl_;
  friend void detail::inject_certificate_fault(MovingBalls&, std::function<void(SurfaceMesh&, std::vector<long>&)>);
};

}  // namespace skinmesh
