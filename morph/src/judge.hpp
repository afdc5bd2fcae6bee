// The one judge of a morph frame's triangles (private to morph/): the
// frame criteria of the static mesher (restricted_triangle,
// triangle_defect) plus the orientation a transported triangle can lose.
// Every rung of the repair (edits, local patch, whole-frame remesh) and both
// engines (Morph, MovingBalls) ask it, so a triangle passes or fails the same
// way wherever it is judged.
#pragma once

#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/surface_mesh.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/morph/relaxation.hpp"

#include <array>
#include <string>
#include <vector>

namespace skinmesh::detail {

// What a triangle fails, grouped by how the edits mend it: size and
// distance by a split, shape first by a contraction or a flip; a triangle
// turned inward or not restricted (`other`) by neither.
enum class Verdict : char { pass, size, shape, inward, other };

// The criteria alone do not see a triangle that transport turned over (a
// vertex moved across its neighbours): it is judged by faces_outward at its
// surface ball centre, not by its corners' normals (across a thin neck a
// good triangle's corner normals can turn past a right angle from its own).
// hint: a cell near the triangle.
Verdict judge_triangle(const SkinComplex& complex, const std::array<Eigen::Vector3d, 3>& corners, int hint,
                       const MeshingOptions& criteria);

inline bool triangle_passes(const SkinComplex& complex, const std::array<Eigen::Vector3d, 3>& corners, int hint,
                            const MeshingOptions& criteria) {
  return judge_triangle(complex, corners, hint, criteria) == Verdict::pass;
}

// Per triangle of `triangles` (corners in `mesh`), 1 where it does not pass, in parallel.
std::vector<char> failing_triangles(const SkinComplex& complex, const SurfaceMesh& mesh,
                                    const std::vector<std::array<int, 3>>& triangles, const MeshingOptions& criteria);

// The triangles of `mesh` marked in `failing` by what they fail (judged
// again, in parallel): what a frame sent to the whole-frame remesh says
// it could not mend.
struct FailingKinds {
  long not_restricted = 0;  // Verdict::other: the normal line through the circumcentre does not cross the skin exactly once within the window
  long shape = 0, size = 0, inward = 0;
  long passing = 0;  // marked, yet passing now
  // "not restricted N, shape N, size or distance N, facing inward N"
  std::string text() const;
};
FailingKinds failing_kinds(const SkinComplex& complex, const SurfaceMesh& mesh, const std::vector<char>& failing,
                           const MeshingOptions& criteria);

// `failing` (from failing_triangles on `mesh` before some of its vertices
// moved) brought up to date: only the triangles with a corner marked in
// `moved` are judged again. A verdict depends on its corners, the first
// corner's cell and the complex alone, so the others keep theirs. Returns
// how many were judged again.
long rejudge_moved(const SkinComplex& complex, const SurfaceMesh& mesh, const std::vector<char>& moved,
                   const MeshingOptions& criteria, std::vector<char>& failing);

// What the caller knows of a transported frame's verdicts, per vertex of
// the mesh (an empty vector: nothing).
struct KnownVerdicts {
  // The vertex did not move, its triangles passed, and the skin within
  // the judge's reach of them is the function it was: the step left the
  // skin and its cells exactly as they were two rings of atoms deep, or no
  // atom that moved is active there before the step or after it
  // (skin_unchanged_near). A triangle with three such corners keeps its
  // verdict unjudged.
  std::vector<char> settled;
  // The vertex moved with the skin around it as one rigid body (two rings
  // of atoms deep, to 1e-9 A; a vertex settled by two rings of still atoms
  // moved by none), and its triangles passed: a triangle whose corners are
  // all carried and whose edges kept their lengths (to 1e-9 A; `before`)
  // sees a congruent skin. The skin criteria, which a congruent triangle
  // meets as it met them, keep its verdict; its angles are judged again, so
  // that the angle bound holds exactly.
  std::vector<char> carried;
  std::vector<Eigen::Vector3d> before;  // the vertices' places before the step (with `carried`)
};

// A transported frame judged, with relaxation only where it is needed (the
// moving-balls engine, whose steps fail a few triangles where atoms meet):
// every triangle judged (as `known` allows), the corners of those that fail
// relaxed along the skin (relaxation.hpp; none when options.passes is 0),
// and the triangles those moves touched judged again in full. The other
// vertices stay on their closed-form paths.
struct Judged {
  std::vector<char> failing;       // per triangle, after the relaxation
  std::vector<char> relaxed;       // per vertex, 1 where the relaxation moved it (empty: none moved)
  long failing_before_relax = 0;   // triangles failing as transported
  long settled = 0;                // triangles taken as passing unjudged (all corners settled)
  long carried = 0;                // triangles judged on their angles alone (KnownVerdicts::carried)
  double seconds_judge = 0, seconds_relax = 0;
};
Judged judge_and_relax(const SkinComplex& complex, SurfaceMesh& mesh, const RelaxationOptions& relaxation,
                       const MeshingOptions& criteria, const KnownVerdicts* known = nullptr);

}  // namespace skinmesh::detail
