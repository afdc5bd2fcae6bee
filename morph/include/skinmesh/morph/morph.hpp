// The morph (GMSSTF, Yan, Cheng et al.; docs/math.md section 4), set up once
// and advanced frame by frame: the complex of B(1/2) of the live pairs is
// built once and moved to each frame (SkinComplex::with_balls); every vertex
// is transported inside its cell (eq. 19) or, where it left its cell,
// projected back onto the new skin; the vertices are relaxed along the skin
// and every triangle is judged by the mesher's own criteria
// (restricted_triangle, triangle_defect).
//
// Repair, cheapest first:
// - a component or void that vanished since the last frame (a critical
//   event of dimension 0 or 3 lowering the Euler characteristic) is dropped
//   with its vertices, when the frame before holds it as a component of its
//   own;
// - failing triangles are mended by edits of the mesh: edge splits at new
//   skin points with Delaunay flips around them, flips, contractions of
//   short edges (RepairPolicy::edits);
// - what the edits leave, and the places where a neck opened or pinched or
//   a component or void was born (dimension 0 or 3, seeded), grown by a
//   ring, are remeshed by restricted Delaunay refinement of their own
//   vertices and stitched back (local repair), the Euler characteristic
//   checked against the events';
// - a frame where that fails or a vertex is lost (its cell's size vanished
//   and no skin point is near) is remeshed as a whole from its transported
//   vertices (remesh_skin): they are kept, those transport crowded together
//   removed, and refinement inserts points only where a triangle fails, and
//   seeds only on skin the vertices miss. Only when that fails is the frame
//   meshed from scratch (FrameStats::full_rebuild).
// Every triangle of every frame meets the frame criteria, whichever path
// made it; `skinmesh morph` also checks each frame as a whole (closed,
// manifold, no self-intersections, every vertex on the skin by the morph
// oracle) before it writes anything.
#pragma once

#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/surface_mesh.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/morph/events.hpp"
#include "skinmesh/morph/relaxation.hpp"
#include "skinmesh/morph/repair_policy.hpp"

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace skinmesh {

struct MorphOptions {
  double shrink = 0.5;      // s in (0,1)
  MeshingOptions first;     // the mesh of the first frame (default: the mesher's 30 degrees)
  // Every later frame is held to these criteria; the smaller angle bound
  // leaves transported triangles room before they need repair.
  MeshingOptions frames = [] {
    MeshingOptions o;
    o.min_angle = 20.0;     // degrees
    return o;
  }();
  // A frame with more than this many times the triangles a fresh mesh of
  // its skin would have (the mesher's own estimate, triangle_estimate.hpp)
  // is meshed afresh, new ids and all: transport onto a shrinking skin never
  // removes a vertex, and one pass of RepairPolicy::crowded_below removes
  // too few.
  // Dimensionless; default 3. Judged only where FrameStats::density, the
  // cheap measure of every frame, passes density_screen (default 4; a mesh
  // the mesher made measures 2-3).
  double max_over_fresh = 3.0;
  double density_screen = 4.0;
  // Every threshold of the repair: crowding, the edits, the local patch
  // (repair_policy.hpp). The blend patches frames with up to 5% of their
  // triangles failing after the edits (at least 200), and a patch's second
  // attempt meshes only around the first one's faults
  // (PatchPolicy::retry_around_faults): a large patch between different
  // molecules is one region that does not stitch at its first attempt, and
  // remeshing that whole region at every attempt costs more than the
  // whole-frame remesh it replaces (docs/morph.md, "What is not there yet").
  // A patch that fails is tried once more with one more ring
  // (PatchPolicy::wider_rings) before the frame is remeshed whole: seam
  // faults a one-ring patch cannot grow past mend with two rings at a
  // fraction of the remesh (bench_morph's 3al1 -> 1ubi at 100 frames,
  // frames 3 and 70).
  RepairPolicy repair = [] {
    RepairPolicy r;
    r.patch.max_failing_share = 0.05;  // a share, 0-1
    r.patch.retry_around_faults = true;
    r.patch.wider_rings = 1;
    return r;
  }();
  // Repairs (local and whole-frame) may refine to stricter criteria than
  // frames are accepted at, so that a repaired triangle has room to move
  // before it fails again: the angle bound raised by the angle margin
  // (degrees; the raised bound at most 30; default 0), epsilon, the edge
  // length cap and the tolerance times the size margin (dimensionless;
  // default 1: none). The first frame's mesh takes its own size margin
  // (default 0.85). Only that one pays: after a first frame meshed with
  // room, frames of a benign motion pass by transport alone, while room at
  // the repairs did not spare repairs and made frames larger and slower.
  // Tangential relaxation after transport, before the triangles are judged
  // (relaxation.hpp; passes = 0: none).
  RelaxationOptions relaxation;
  double repair_angle_margin = 0.0;  // degrees
  double repair_size_margin = 1.0;
  double first_size_margin = 0.85;
  MeshingOptions repair_criteria() const;
  MeshingOptions first_criteria() const;  // `first` with the first frame's size margin
};

struct FrameStats {
  double t = 0;
  long vertices = 0, triangles = 0;
  long moved = 0;              // transported inside their cell (exactly onto the new skin)
  long relocated = 0;          // left their cell (or its size vanished) and were projected onto the new skin
  long bad_triangles = 0;      // failing the frame's criteria after the move
  long crowded = 0;            // vertices removed at the repair because transport crowded them
  long lost = 0;               // vertices that could not be put on the new skin (removed)
  long events = 0;             // critical topology events since the previous frame
  long necks = 0;              // of them, necks that opened or pinched mended by surgery
  long births = 0;             // of them, components and voids born meshed as spheres by surgery
  long surgeries_undone = 0;   // necks and births undone: the edits and the patch could not finish the frame (moving atoms)
  bool repaired = false;       // failing triangles were repaired (locally, or by remeshing)
  long patch_triangles = 0;    // triangles replaced by the local repair
  bool remeshed = false;       // the whole frame was remeshed from its transported vertices
  long inserted = 0;           // new vertices (refinement and seeds)
  long removed = 0;            // vertices of the previous frame not in this one
  long repairs = 0;            // refinement insertions, each at a failing triangle
  long split = 0, flipped = 0, contracted = 0;  // edits that mended failing triangles
  bool full_rebuild = false;   // the frame was meshed from scratch (repair failed, or too dense)
  double density = 0;          // triangles over those a fresh mesh of the frame's skin would have (2-3 fresh)
  bool thinned = false;        // meshed afresh (full_rebuild): more than max_over_fresh times a fresh mesh's triangles
  // Moving balls (moving_balls.hpp) only:
  long steps = 0;              // internal steps since the frame before (each a complex built from scratch)
  long built_ahead = 0;        // of them, whose complex was built beside the step before's repair
  long reidentified = 0;       // vertices that moved farther than continuity allows and took a new id
  long settled = 0;            // triangles in skin the step left as it was, kept as passing unjudged
  long carried = 0;            // triangles in skin the step moved as one rigid body: angles judged again, the rest kept
  double ids_kept = 0;         // share of the frame's vertices whose id the frame before had
  double max_kept_move = 0;    // largest move of a vertex whose id was kept, since the frame before (Angstrom)
  bool topology_certified = false;  // components, voids and Euler characteristic equal the skin's (skin_topology)
  std::string remeshed_because;     // why the last step remeshed whole was not mended locally ("" when none was)
  // Where the frame's time went (seconds; `frames.jsonl` in docs/morph.md,
  // "The output directory"). The stages do not overlap; their sum falls
  // short of `seconds` by the bookkeeping between them and by the wait for
  // the complex moved ahead (advance_to's next_t).
  double seconds = 0;            // the whole frame
  double seconds_complex = 0;    // the frame's complex moved to t (0 when moved ahead during the frame before)
  double seconds_transport = 0;  // every vertex transported or put on the new skin, vanished components dropped
  double seconds_relax = 0;      // tangential relaxation
  double seconds_judge = 0;      // every triangle judged against the frame's criteria
  double seconds_repair = 0;     // mending: edits, local repair, whole-frame remesh or rebuild
  // Of seconds_repair: the edits (splits, flips, contractions, thinning,
  // neck surgery) and the local patches (every attempt, those of a patch
  // that failed too); the rest is a whole-frame remesh or rebuild.
  double seconds_edits = 0;
  double seconds_patch = 0;
  long patch_attempts = 0;       // restricted Delaunay refinements of a patch region with its context
};

struct MorphFrame {
  SurfaceMesh mesh;            // cells index the frame's complex (same numbering in every frame)
  std::vector<long> ids;       // per vertex: kept while the vertex survives, never reused
  FrameStats stats;
};

class Morph;
namespace detail {
// For tests only: `fault` is applied to every mesh of a frame remeshed
// whole or meshed from scratch after a remesh, with the frame's ids, just
// before its topology certificate.
void inject_remesh_fault(Morph& morph, std::function<void(SurfaceMesh&, std::vector<long>&)> fault);
}  // namespace detail

class Morph {
 public:
  // Moves the mesh to frame t, later than the current one and at most 1.
  // Throws ContractError otherwise. Inside (0,1) the vertices are
  // transported in the overlay complex; at t = 1 (and from a first frame at
  // t = 0) the overlay degenerates to the target's (source's) complex, so the
  // vertices are projected onto the other complex's skin and the frame is
  // remeshed from them.
  //
  // `next_t`, when given (in (t, 1)), is the frame that will be asked for
  // after this one: its complex is then moved while this frame is repaired,
  // on the core the mostly serial repairs leave idle, and advance_to(next_t)
  // starts from it. The frames are the same either way. A Morph whose
  // advance_to threw (a frame the mesher could not make: Error) holds no
  // valid frame and is not to be advanced again.
  const MorphFrame& advance_to(double t, double next_t = -1);
  double t() const;
  // Per vertex of the current frame: the source atom and the target atom it
  // belongs to (the pair of the cell's ball of least power distance, the
  // paper's surface point correspondence). At t = 0 and t = 1 the frame's
  // complex is one side's own: the other side's atom is -1 there.
  std::vector<std::array<int, 2>> vertex_atoms() const;
  const MorphFrame& frame() const;
  const SkinComplex& complex() const;
  const std::vector<TopologyEvent>& events() const;
  const std::vector<BallPair>& pairs() const;
  // The complex of B(1/2) of the live pairs, whose cells every frame in
  // (0,1) has, and per cell its size and centre as functions of t.
  const SkinComplex& middle_complex() const;
  const std::vector<CellSize>& sizes() const;

  // A Morph moves; it is not copied (its state holds three complexes).
  Morph(Morph&&) noexcept;
  Morph& operator=(Morph&&) noexcept;
  ~Morph();

 private:
  struct Impl;  // morph.cpp: the complexes, the events, the frame and the repair ladder
  explicit Morph(std::unique_ptr<Impl> impl);
  friend Morph prepare_morph(std::vector<Ball> source, std::vector<Ball> target, double t0,
                             const MorphOptions& options);
  std::unique_ptr<Impl> impl_;
  friend void detail::inject_remesh_fault(Morph&, std::function<void(SurfaceMesh&, std::vector<long>&)>);
};

// Live pairs, the complex of B(1/2), the topology events, and the first
// frame at t0 in [0,1) meshed by the mesher (at t0 = 0: the source's own
// skin). The balls should be aligned already (alignment.hpp). Throws
// ContractError for t0 outside [0,1) or empty ball sets; a first frame the
// mesher cannot make throws Error with its message.
Morph prepare_morph(std::vector<Ball> source, std::vector<Ball> target, double t0, const MorphOptions& options = {});

}  // namespace skinmesh
