// The quality skin mesher: restricted Delaunay refinement on the exact skin
// (in the style of H.-L. Cheng and X. Shi, "Quality mesh generation for molecular
// skin surfaces using restricted union of balls", and J.-D. Boissonnat and S.
// Oudot, "Provably good sampling and meshing of surfaces", Graph. Models 2005).
//
// Samples lie exactly on the skin. Their 3D Delaunay triangulation (CGAL, kept
// inside the implementation) restricted to the skin is the mesh: a triangle for
// every Delaunay facet whose dual Voronoi edge crosses the skin, and the
// crossing is the centre of the triangle's "surface Delaunay ball". Refinement
// inserts that centre while a triangle is too big for the local curvature, too
// far from the skin, has a smallest angle under the bound, or the topology
// conditions fail (a Voronoi edge crossing the skin twice, a vertex whose
// triangles are not one disk). Every component of the skin is seeded by the
// points where its normal takes four fixed directions, which every closed
// component has.
#pragma once

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/sizing.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/surface_mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace skinmesh {

struct MeshingProgress {
  const char* stage = "";      // "seeding", "refining", "checking"
  long vertices = 0;
  long pending = 0;            // bad triangles waiting in the queue
  // Vertices the finished mesh is expected to have, from the estimate made
  // before refinement (triangle_estimate.hpp; within about 25% either way);
  // 0 when not known.
  double expected_vertices = 0;
};

struct MeshingOptions {
  double min_angle = 30.0;     // degrees: every triangle's smallest angle at least this (at most 30)
  // Sizing: the curvature-relative size (edge ~ epsilon / max |curvature|,
  // clamped to [min_size, max_size]), capped at edge_length (Angstrom) when
  // that is > 0. The cap never loosens the curvature bound, which is what
  // keeps the topology.
  double edge_length = 0.0;
  SizingOptions sizing;
  // Largest distance (Angstrom) between a triangle's circumcentre and the skin
  // along the triangle's normal line (its Voronoi edge).
  double tolerance = 0.1;
  // Clean-up (Cheng-Shi): restricted edges shorter than this times the local
  // target edge length are contracted to a skin point when every guarantee
  // still holds around them. Dimensionless; 0 (the default) leaves it out:
  // it removes few triangles for much more time (bench_mesher's
  // contraction column).
  double contract_below = 0.0;
  // Refinement stops (status over_budget) past this many triangles, and a
  // job whose estimate (triangle_estimate.hpp) passes it even at the low end
  // of the estimate's spread is refused before refinement.
  long max_triangles = 4'000'000;
  // Bytes: a job whose estimated peak memory passes this, even at the low end
  // of the estimate's spread, is refused before refinement; 0: no limit.
  double max_memory_bytes = 0;
  int threads = 0;             // 0: all hardware threads
  std::function<void(const MeshingProgress&)> progress;  // called now and then, from the calling thread
};

// The mesher's criteria for one triangle, public so that every frame of a
// morph is judged exactly as the mesher judges its own triangles.
//
// A restricted triangle and its surface Delaunay ball: the ball's centre is
// where the triangle's dual Voronoi edge (in a mesh without its Delaunay
// triangulation: the triangle's normal line through its circumcentre) crosses
// the skin; its radius is the distance from there to the corners.
struct RestrictedTriangle {
  std::array<Eigen::Vector3d, 3> corners;                    // on the skin
  Eigen::Vector3d ball_center = Eigen::Vector3d::Zero();     // on the skin
  int ball_cell = -1;                                        // mixed cell of ball_center
  int crossings = 1;                                         // of the dual edge with the skin
};

enum class TriangleDefect : unsigned char {
  none,
  topology,  // the dual edge crosses the skin more than once
  size,      // surface Delaunay ball radius > target edge length / sqrt(3)
  distance,  // circumcentre farther than the tolerance (with its margin) from the skin
  shape,     // circumradius / shortest edge above 1 / (2 sin(min_angle))
};
const char* triangle_defect_name(TriangleDefect defect);

// A triangle of a mesh kept without its Delaunay triangulation (a frame of a
// morph) as a restricted triangle: its surface ball centre taken where the
// triangle's normal line through its circumcentre crosses the skin, nearest
// the circumcentre, within `reach` Angstrom of it and no farther than its
// circumradius (crossings counts those within that window; one farther is
// another piece of skin). Empty when the corners are collinear or no
// crossing is in the window. hint: a cell near the triangle (a corner's).
std::optional<RestrictedTriangle> restricted_triangle(const SkinComplex& complex,
                                                      const std::array<Eigen::Vector3d, 3>& corners, double reach,
                                                      int hint = -1);

// The shape criterion alone, as triangle_defect applies it: circumradius
// over shortest edge at most 1 / (2 sin(min_angle)), corners not collinear.
// It needs no skin: a cheap first test of a triangle an edit would make.
bool shape_passes(const std::array<Eigen::Vector3d, 3>& corners, double min_angle);

// The first criterion the triangle fails, in the order above, or none.
TriangleDefect triangle_defect(const SkinComplex& complex, const RestrictedTriangle& triangle,
                               const MeshingOptions& options);

// Whether the triangle, corners in their order, faces the way the skin's
// gradient points at its surface ball centre. The criteria above do not see
// orientation: a triangle turned over (a morph's transport moved a corner
// across its neighbours) meets them as well as the right one does.
bool faces_outward(const SkinComplex& complex, const RestrictedTriangle& triangle);

// The target edge length (Angstrom) at a skin point x of `cell`.
double target_edge_length(const SkinComplex& complex, const Eigen::Vector3d& x, int cell,
                          const MeshingOptions& options);

struct MeshingStats {
  long seeds = 0;
  long inserted_size = 0, inserted_shape = 0, inserted_distance = 0;
  long inserted_topology = 0;      // Voronoi edges crossing twice, non-disk vertex stars, isolated samples
  int passes = 0;                  // global verification passes over all Delaunay facets
  long contracted = 0;             // short edges contracted by the clean-up
  long contraction_attempts = 0;   // short edges tried (the others would have broken a guarantee)
  double seconds_seeding = 0, seconds_refining = 0, seconds_contracting = 0, seconds_total = 0;
};

// Expected ways for refinement to end without a mesh.
enum class MeshingStatus {
  ok,
  over_budget,   // the mesh would pass MeshingOptions::max_triangles
  stalled,       // bad triangles left whose surface Delaunay ball centres are samples already (rounding)
  unrepairable,  // a sample with no restricted triangle and no point to repair it with
  empty_skin,    // no ball has a positive weight: F >= 0 everywhere, there is no surface to mesh
};
const char* meshing_status_name(MeshingStatus status);

// Thrown by callers that mesh inside a longer job (a morph's frames) when
// the mesher returns a status other than ok: the status says which, so that
// a command can answer as `mesh` does (an empty skin is bad input, a
// budget refusal a job refused).
class MeshingFailed : public Error {
 public:
  MeshingFailed(MeshingStatus status, const std::string& message) : Error(message), status(status) {}
  MeshingStatus status;
};

// Size options changed, together, to values at which the estimate, even at
// the high end of its spread, fits the budget: what a refused job could ask
// for.
enum class SizeOption { tolerance, epsilon, edge_length, max_size, min_size };
const char* size_option_name(SizeOption option);
struct SizeChange {
  SizeOption option;
  double value;                    // Angstrom, or dimensionless for epsilon
};
struct FittingSize {
  std::vector<SizeChange> changes; // one option alone, or all sizes scaled together
};

struct SkinMeshResult {
  MeshingStatus status = MeshingStatus::ok;
  std::string message;             // what happened, when status != ok (names no command-line flag)
  double estimated_triangles = 0;  // the estimate made before refinement (mesh_skin; 0 for remesh_skin)
  // over_budget before refinement: size changes that would fit, each option
  // alone where one can, else all sizes scaled together (empty when nothing
  // fits: the skin has more small patches than the budget).
  std::vector<FittingSize> fitting_sizes;
  // over_budget before refinement with no size that fits, because the skin's
  // creases (a shrink factor near 1) need the triangles whatever the sizes:
  // the largest shrink factor that would fit, else 0.
  double fitting_shrink = 0;
  SurfaceMesh mesh;                // triangles oriented outward; normals and mixed cells per vertex; empty unless ok
  MeshingStats stats;
  // remesh_skin only: per vertex of `mesh`, the index of the given sample it
  // is, or -1 for a vertex that refinement or seeding added.
  std::vector<long> origins;
};

// Throws ContractError for options out of range.
SkinMeshResult mesh_skin(const SkinComplex& complex, const MeshingOptions& options = {});

// A point on the skin and its mixed cell.
struct SkinSample {
  Eigen::Vector3d point;
  int cell = -1;
};

// Restricted Delaunay refinement started from given samples on the skin (a
// morph frame's transported vertices) instead of from seeds alone: the
// samples are inserted in one spatially sorted batch, seeds are added only
// where no sample lies within a target edge length (a component the samples
// miss), and refinement then inserts points only where a restricted triangle
// fails a criterion. Every guarantee of mesh_skin holds for the result; the
// samples are kept (a sample without restricted triangles is dropped) and
// result.origins says which output vertex is which sample. A sample off the
// skin (|F| above rounding) is projected onto it first. Throws ContractError
// for options out of range.
SkinMeshResult remesh_skin(const SkinComplex& complex, const std::vector<SkinSample>& samples,
                           const MeshingOptions& options = {});

// Local repair of one patch of a mesh (a morph frame's failing region): the
// patch's vertices and a ring of context vertices around it are
// triangulated; only facets whose corners are all patch vertices or inserted
// points are judged and refined, and only interior vertices (whose whole
// star lies in the patch) must have disk stars. The caller stitches the
// triangles into the rest of the mesh and checks the seam.
enum class PatchRole : char {
  interior,  // in the patch, with its whole star
  boundary,  // in the patch, on its rim: part of its star stays outside
  context,   // outside the patch: shapes the Delaunay triangulation only
};
struct PatchMeshResult {
  MeshingStatus status = MeshingStatus::ok;
  std::string message;
  std::vector<SkinSample> added;              // points refinement inserted
  // Restricted triangles among patch vertices, outward; a corner below
  // samples.size() is that sample, any other samples.size() + k is added[k].
  std::vector<std::array<long, 3>> triangles;
  MeshingStats stats;
};
// The refinement stops (status stalled) once it has inserted more than
// twice the patch's own points (its context not counted) plus 64, or more
// than `least_budget` points when that is larger: a caller that meshes a
// patch again in pieces keeps the budget the whole patch had.
// `within` (Angstrom, one per sample, context samples' unused; empty: no
// bound) keeps the refinement near the patch when the context covers only
// the skin near it: a facet counts only where its Voronoi edge, looked at
// within twice the facet's circumradius of it, crosses the skin within
// within[i] of a patch sample i. Without it, the context must cover the
// skin any patch facet's Voronoi edge can reach, or refinement runs on
// into skin the rest of the mesh covers.
PatchMeshResult mesh_patch(const SkinComplex& complex, const std::vector<SkinSample>& samples,
                           const std::vector<PatchRole>& roles, const MeshingOptions& options = {},
                           long least_budget = 0, const std::vector<double>& within = {});

}  // namespace skinmesh
