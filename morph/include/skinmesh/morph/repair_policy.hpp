// Every threshold of the repair a morph frame goes through, cheapest rung
// first (docs/morph.md, "Repair"), for both engines: the m x n morph
// (morph.hpp) and moving balls (moving_balls.hpp). Defaults are the
// measured choices; each field says what it trades.
#pragma once

namespace skinmesh {

// Edits of the mesh itself: an edge split at a new skin point with Delaunay
// flips around it, a flip, the contraction of a short edge (docs/morph.md,
// "Mending by edits"). Every edit keeps the mesh closed, oriented and
// manifold and its topology; what the edits cannot mend goes on to the
// local patch.
struct EditPolicy {
  bool enabled = true;  // false: no edits; failing triangles go to the patch or the remesh
  // A failing triangle whose shortest edge is below this times the target
  // edge length at its ends is mended by contracting that edge (transport
  // crowds vertices where a patch shrinks) before a split is tried.
  double contract_below = 0.5;  // dimensionless
  // Edits at most this many times the failing triangles (plus 64), so that
  // edits that chase each other stop; what is left stays failing.
  long edits_per_failing = 12;
  // A triangle made by an edit is mended in turn, down to this many
  // generations from a triangle that failed after transport; past it the
  // edits are chasing each other and the triangle is left failing.
  int generations = 3;
  // Then every edge shorter than this times the target edge length at its
  // ends is contracted where every triangle left passes; 0: none.
  double thin_below = 0.5;  // dimensionless
  // A thinning contraction refused in an earlier frame is tried again only
  // when its edge has shrunk by this share since, or after this many frames.
  // Most short edges are refused frame after frame, each refusal judging a
  // fan of triangles: they are short by design where the mesh was refined
  // with room.
  double retry_shrink = 0.05;  // a share
  int retry_after_frames = 8;  // frames
};

// The local patch: the triangles still failing (and the places where the
// topology changed), grown by rings, remeshed by restricted Delaunay
// refinement of their own vertices and stitched back (docs/morph.md).
struct PatchPolicy {
  // A patch is tried when at most this share of the triangles fails after
  // the edits (a share, 0-1; 0, with always_patch_up_to 0: never); past it
  // the patches cover much of the mesh and remeshing the whole frame from
  // its vertices is faster. Moving atoms take these defaults; the blend
  // takes a share of 0.05 (MorphOptions::repair).
  double max_failing_share = 0.01;
  // ... or at most this many triangles, whatever the share (a count; 0:
  // the share alone). On a small frame the share is a few dozen triangles,
  // a patch of which costs a fraction of remeshing the frame whole: the
  // blend of 2k39 model 1 -> 3 in 101 frames remeshed 5 frames whole with
  // the share alone and 1 with 200, pept -> 3al1 42 and 31, in the same
  // time within the spread between runs.
  long always_patch_up_to = 200;
  // Rings of triangles around the failing ones that join the patch (a
  // count): one ring mends as many frames as two, at less cost, and none
  // mends fewer.
  int rings = 1;
  // A patch that failed (other than by taking nearly the whole frame, or
  // with its seam holding and the topology wrong) is tried once more from
  // the start with this many more rings (a count; 0: not), before the frame
  // is remeshed whole. A wider region moves the seam off faults the narrow
  // one could not grow past; a patch whose seam held with the wrong Euler
  // characteristic ended the same way with more rings each time on
  // bench_moving's DNA motion (3 of 3, at 41 and 101 frames), after costing
  // about as much as the first round. Both engines turn it on
  // (MovingOptions::repair, MorphOptions::repair).
  int wider_rings = 0;
  // The patch grown around the seam's faults at most this many times;
  // past the fourth, not after two attempts in a row that left no fewer
  // faults than the fewest before.
  int attempts = 10;
  // After an attempt that left faults, the pieces of the patch that hold (no
  // fault; kept triangles part them from the rest) go into the mesh, and the
  // next attempt remeshes only the others, grown around their faults. Most
  // of a patch holds at the first attempt, so later attempts cost a
  // fraction of it. A piece whose refinement runs away alone (stalls) is
  // tried once more with the whole region. false: every attempt remeshes
  // the whole region.
  bool retry_in_pieces = true;
  // Finer still (with retry_in_pieces): after a first attempt that left
  // faults, all its triangles go into the mesh, and the next attempt
  // remeshes only the triangles (old or new) around the vertices where the
  // seam or a new triangle failed; later attempts go on in pieces. The
  // frame is taken only when every vertex the first attempt touched ends
  // with one disk of triangles. The first attempt is most of a patch's
  // work, and nearly all of it holds. Moving atoms and the blend turn it
  // on (moving_balls.hpp, morph.hpp).
  bool retry_around_faults = false;
  // A patch whose refinement stalls (it needs more than twice its own
  // points: most often it meshes the far side of a thin gap that its
  // context did not reach) is tried once more over the same region with
  // the context's reach times this (dimensionless; 1: not tried again). On
  // bench_moving's 3mht motions at 101 frames 2 left 4 and 15 frames
  // remeshed whole instead of 13 and 18.
  double stalled_reach_scale = 2.0;
  // A point the patch's refinement inserted whose star does not close
  // lacks triangles whose third corner is context (the patch keeps only
  // triangles among its own vertices), and growing the patch around the
  // star's corners does not reach that context. The patch grows over the
  // patch and context vertices within this times the star's longest edge
  // instead (dimensionless; 0: around the star's corners only).
  double open_star_reach = 2.0;
  // A patch whose samples (with their context) pass this share of the
  // frame's vertices is not tried (a share, 0-1): it is nearly the whole
  // frame, which the whole-frame remesh does once, where a patch may be
  // tried `attempts` times. For the blend, lower would also refuse patches
  // of a third to a half of the frame, which often succeed cheaply there;
  // moving atoms take 0.3 (moving_balls.hpp).
  double max_sample_share = 0.9;
  // A patch is first tried with a local context: at each patch vertex the
  // mesh vertices within twice the longest region edge within two rings of
  // it, and the refinement held within half that distance of the patch
  // (mesh_patch's `within`), so that it cannot run into skin the context
  // does not hold. When that fails (not for want of room: a larger context
  // would not fit either), the patch is tried again with the region's
  // longest edge as the measure at every vertex. false: only the latter.
  // A region with one stretched triangle otherwise takes a context of tens
  // of thousands of vertices for a few hundred of its own.
  bool local_context_first = true;
  // The local context's reach (above) at a patch vertex is at most this
  // many target edge lengths there (dimensionless; 0: no cap). A region
  // triangle that transport stretched across a topology change otherwise
  // sets a reach of several Angstrom for every vertex within two rings of
  // it, and the context then holds thousands of vertices far from where
  // anything is meshed. Moving atoms take 6 (moving_balls.hpp).
  double local_reach_cap = 0;
  // The context's reach: at each patch vertex, the mesh vertices within
  // this times the measure there (the longest region edge nearby, above)
  // join the patch's Delaunay triangulation (dimensionless). It should span
  // the surface Delaunay ball of a facet at the vertex, whose diameter is
  // about the facet's longest edge over the sine of its largest angle: 2
  // spans largest angles up to 150 degrees, 1.5 up to 138. A smaller reach
  // inserts fewer context points at every attempt. Moving atoms take 1.5
  // (moving_balls.hpp).
  double context_reach = 2.0;
};

struct RepairPolicy {
  // At a patch or a whole-frame remesh, a transported vertex nearer than
  // this times the target edge length to a neighbour along a mesh edge is
  // removed (transport crowds vertices where a patch shrinks; refinement
  // puts back what the criteria need). Dimensionless. Lower lets the vertex
  // count grow frame after frame; higher leaves frames coarser, not faster.
  double crowded_below = 0.5;
  // A neck that opens or pinches in a step is cut and joined or capped
  // (morph/src/necks.hpp) before the edits, which refine the new triangles;
  // false: the local patch remeshes around it. Needs the edits. Moving atoms
  // take it (moving_balls.hpp); the blend's frames, whose patches mend many
  // other triangles besides, took longer with it (docs/morph.md).
  bool neck_surgery = false;
  // A component or a void born in a step (a critical event of dimension 0
  // or 3) is meshed as a sphere of its own (morph/src/births.hpp), every
  // triangle judged; false: the local patch remeshes around it. Needs the
  // edits.
  bool birth_surgery = true;
  EditPolicy edits;
  PatchPolicy patch;
};

}  // namespace skinmesh
