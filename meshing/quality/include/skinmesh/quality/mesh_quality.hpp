// Grading a triangle mesh, ours or another tool's: element quality, size,
// topology (components, Euler characteristic, genus), defects (boundary and
// non-manifold edges and vertices, inconsistent orientation, zero-area
// triangles) and self-intersections.
#pragma once

#include "skinmesh/core/skin_topology.hpp"
#include "skinmesh/core/surface_mesh.hpp"

#include <map>
#include <vector>

namespace skinmesh {

struct Histogram {
  double lo = 0, hi = 0;       // range of the bins
  std::vector<long> counts;    // equal-width bins
};

struct MeshQuality {
  long vertices = 0, triangles = 0, edges = 0;
  double min_angle = 0, max_angle = 0;       // degrees, over all triangles
  double mean_min_angle = 0;                 // degrees, mean of each triangle's smallest angle
  double share_below_20 = 0, share_below_10 = 0;  // share of triangles whose smallest angle is below
  double max_radius_edge = 0;                // circumradius / shortest edge (1/sqrt(3) when equilateral)
  double max_aspect = 0;                     // circumradius / (2 inradius) (1 when equilateral)
  double min_edge = 0, mean_edge = 0, max_edge = 0;  // Angstrom
  std::map<int, long> valence;               // triangles around a vertex -> vertices
  double area = 0;                           // Angstrom^2
  double volume = 0;                         // Angstrom^3, signed (positive for outward triangles)
  long components = 0;
  long cavities = 0;                         // components enclosing negative volume (inner surfaces of voids)
  long euler = 0;                            // V - E + F (vertices used by triangles)
  long genus = -1;                           // total genus; -1 unless closed, manifold, oriented
  long boundary_edges = 0, nonmanifold_edges = 0, nonmanifold_vertices = 0;
  long inconsistent_edges = 0;               // edges whose two triangles run them the same way
  long degenerate_triangles = 0;             // zero area
  long unused_vertices = 0;
  bool closed = false, manifold = false, oriented = false;
  bool self_intersections_checked = false;   // exact check needs a manifold mesh
  long self_intersecting_pairs = 0;
  // The exact check stopped at GradeOptions' bound on box pairs: not checked.
  bool self_intersections_over_bound = false;
  long self_intersection_box_pairs = 0;      // pairs of triangles with overlapping boxes examined
  // Triangles whose pairs the exact check tested: all, or the changed ones
  // (GradeOptions::changed).
  long self_intersection_triangles_tested = 0;
  Histogram min_angle_histogram;             // 0-60 degrees, 12 bins
};

enum class SelfIntersectionCheck { exact, skip };  // exact: CGAL's predicates, O(n log n) with box intersection

// The exact check examines every pair of triangles whose bounding boxes
// overlap: about 6 per triangle on a skin mesh (6.2-6.3 on pept, 1ubi and
// 3al1), but up to the square of the size on a hostile one (thousands of
// copies of one body), where the check would grind for minutes. It stops
// past this many pairs per triangle on average (and never below
// kMinBoxPairs in all, so that a small mesh is always checked).
inline constexpr double kDefaultBoxPairsPerTriangle = 100;
inline constexpr long kMinBoxPairs = 1'000'000;

struct GradeOptions {
  SelfIntersectionCheck self_intersections = SelfIntersectionCheck::exact;
  double max_box_pairs_per_triangle = kDefaultBoxPairsPerTriangle;
  // Per triangle, 1 where it changed since a frame whose triangles were all
  // certified (CertifiedTriangles): only pairs with a changed triangle are
  // tested (check_changed_self_intersections). Null: every pair.
  const std::vector<char>* changed = nullptr;
  // The bound in pairs for a mesh of `triangles` triangles.
  long max_box_pairs(long triangles) const;
};

MeshQuality grade_mesh(const SurfaceMesh& mesh, const GradeOptions& options = {});

// Exact self-intersection check (CGAL's exact predicates on the pairs of
// triangles whose bounding boxes meet, found by a uniform grid, or by
// CGAL's box intersection where the boxes' sizes differ too much for a
// grid): the triangle pairs that meet in more than the vertices and edge
// they share by index. Memory grows with the mesh, not with the pairs.
struct SelfIntersectionCount {
  long pairs = 0;           // crossing pairs (incomplete when over_bound)
  long box_pairs = 0;       // pairs of overlapping boxes examined (by CGAL's slabs, a pair in two slabs twice)
  bool degenerate = false;  // a triangle with two equal indices or collinear corners: no answer
  bool over_bound = false;  // stopped after max_box_pairs box pairs: no answer
  bool by_grid = false;     // the box pairs came from the grid, not from CGAL's box intersection
};
SelfIntersectionCount check_self_intersections(const SurfaceMesh& mesh, long max_box_pairs);
// The same over the pairs with a `changed` triangle (per triangle, 1 or
// 0) alone: when the unchanged triangles met only at shared corners in a
// mesh checked before, where they were (CertifiedTriangles), this is the
// count over every pair. Degenerate: a changed triangle is.
SelfIntersectionCount check_changed_self_intersections(const SurfaceMesh& mesh, const std::vector<char>& changed,
                                                       long max_box_pairs);
// The same without a bound: the number of crossing pairs, or -1 when a
// triangle is degenerate, where the question has no answer.
long count_self_intersections(const SurfaceMesh& mesh);

// The connected components of a mesh's triangles (through shared vertices)
// and the signed volume each encloses: with outward normals, a closed
// component enclosing negative volume is the inward-facing surface of a cavity.
struct SurfaceComponents {
  std::vector<int> of_triangle;          // component of each triangle, 0-based
  std::vector<double> enclosed_volume;   // Angstrom^3 per component, signed
  bool is_cavity(int component) const { return enclosed_volume[static_cast<size_t>(component)] < 0; }
};
SurfaceComponents surface_components(const SurfaceMesh& mesh);

// Components, voids and Euler characteristic of a closed triangle mesh
// (voids: components enclosing negative volume, the triangles outward), as
// the skin's are counted (skin_topology.hpp): a morph frame's certificate.
// Only the mesh's numbers; grade_mesh says whether it is closed.
SkinTopology mesh_topology(const SurfaceMesh& mesh);

// Per component of a closed mesh: whether another component encloses it
// (the winding number of one of its vertices about that component's
// triangles is not 0): a cavity's surface, an island inside a cavity. The
// components no other encloses are the outer surface.
std::vector<char> enclosed_components(const SurfaceMesh& mesh, const SurfaceComponents& components);
// The mesh without its enclosed components; `kept_from` (when given) gets
// each kept vertex's index in `mesh`.
SurfaceMesh outer_surface(const SurfaceMesh& mesh, std::vector<int>* kept_from = nullptr);

}  // namespace skinmesh
