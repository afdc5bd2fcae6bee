// The morph's repair stages on their own, through their private headers
// (morph/src/surgery.hpp, local_repair.hpp): the edits' thinning, where an
// edge whose contraction was refused is not tried again in the next frame
// unless it has shrunk or its refusal has aged; and the local repair, which
// leaves a patch that is nearly the whole frame to the whole-frame remesh
// and, after an attempt with faults, meshes again only the pieces that had
// them and grows over the context near a new point whose star does not close;
// the sphere a birth adds (births.hpp).
#include <catch2/catch.hpp>

#include "test_support.hpp"
#include "four_balls.hpp"

#include "skinmesh/core/skin_oracle.hpp"
#include "skinmesh/core/skin_topology.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/morph/moving_balls.hpp"
#include "skinmesh/quality/guarantees.hpp"
#include "skinmesh/quality/mesh_quality.hpp"
#include "births.hpp"
#include "judge.hpp"
#include "local_repair.hpp"
#include "mesh_part.hpp"
#include "surgery.hpp"
#include "vanishing.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <optional>
#include <set>

using namespace skinmesh;

namespace {

// pept's skin meshed at the mesher's 30 degrees, to be judged at the frames'
// 20: the refinement leaves edges under half the target length, most of
// which cannot go without a triangle failing.
struct PeptFrame {
  SkinComplex complex;
  SurfaceMesh mesh;
  MeshingOptions accept;
};

PeptFrame pept_frame() {
  PeptFrame f{build_skin_complex(test::centred_model(test::data_file("pept.pdb"), 1)), {}, {}};
  SkinMeshResult made = mesh_skin(f.complex, MeshingOptions{});
  REQUIRE(made.status == MeshingStatus::ok);
  f.mesh = std::move(made.mesh);
  f.accept.min_angle = 20;
  return f;
}

}  // namespace

TEST_CASE("edits: thinning skips an edge refused in the frame before until it shrinks or its refusal ages",
          "[morph]") {
  const PeptFrame f = pept_frame();
  const SkinComplex& complex = f.complex;
  const MeshingOptions& accept = f.accept;
  std::vector<long> ids(f.mesh.vertices.size());
  std::iota(ids.begin(), ids.end(), 100);
  const std::vector<char> none_failing(f.mesh.triangles.size(), 0);
  const EditPolicy options;
  auto thin = [&](detail::RefusedEdges& refused) {
    return detail::mend_by_edits(complex, f.mesh, none_failing, accept, options, &ids, &refused);
  };

  detail::RefusedEdges refused;
  const detail::RepairResult first = thin(refused);
  REQUIRE(first.thin_tried > 0);
  REQUIRE(!refused.empty());
  const long refused_first = static_cast<long>(refused.size());
  CHECK(refused_first < first.thin_tried);  // some were contracted

  SECTION("the same frame again: none of the refused edges is tried") {
    const detail::RefusedEdges before = refused;
    const detail::RepairResult second = thin(refused);
    // An edge is skipped even where a contraction beside it would have let
    // it go later in the pass; so at most the others are tried.
    CHECK(second.thin_tried <= first.thin_tried - refused_first);
    CHECK(second.counts.contractions > 0);
    for (const auto& [edge, memo] : before) {
      const auto carried = refused.find(edge);
      REQUIRE(carried != refused.end());
      CHECK(carried->second.first == memo.first);
      CHECK(carried->second.second == 1);  // a frame older
    }
  }
  SECTION("edges shorter than when refused are tried again") {
    for (auto& [edge, memo] : refused) memo.first /= 1 - 2 * options.retry_shrink;
    CHECK(thin(refused).thin_tried == first.thin_tried);
  }
  SECTION("a refusal as old as retry_after_frames is tried again") {
    for (auto& [edge, memo] : refused) memo.second = options.retry_after_frames - 1;
    CHECK(thin(refused).thin_tried == first.thin_tried);
  }
  SECTION("without ids every short edge is tried") {
    const detail::RepairResult plain = detail::mend_by_edits(complex, f.mesh, none_failing, accept, options);
    CHECK(plain.thin_tried == first.thin_tried);
  }
}

TEST_CASE("edits: with still marks, thinning tries only edges near a vertex that is not still", "[morph]") {
  const PeptFrame f = pept_frame();
  const std::vector<char> none_failing(f.mesh.triangles.size(), 0);
  const EditPolicy options;
  const size_t n = f.mesh.vertices.size();
  auto thin = [&](const std::vector<char>* still) {
    return detail::mend_by_edits(f.complex, f.mesh, none_failing, f.accept, options, nullptr, nullptr, still);
  };
  const detail::RepairResult plain = thin(nullptr);
  REQUIRE(plain.thin_tried > 0);
  REQUIRE(plain.counts.contractions > 0);

  SECTION("every vertex still: no edge is tried and the mesh is kept") {
    const std::vector<char> all(n, 1);
    const detail::RepairResult kept = thin(&all);
    CHECK(kept.thin_tried == 0);
    CHECK(kept.counts.contractions == 0);
    CHECK(kept.mesh.triangles == f.mesh.triangles);
  }
  SECTION("no vertex still: the same as without marks") {
    const std::vector<char> none(n, 0);
    const detail::RepairResult same = thin(&none);
    CHECK(same.thin_tried == plain.thin_tried);
    CHECK(same.mesh.triangles == plain.mesh.triangles);
  }
  SECTION("half the vertices still: only edges with an end near the other half are tried") {
    std::vector<double> x(n);
    for (size_t v = 0; v < n; ++v) x[v] = f.mesh.vertices[v].x();
    std::vector<double> sorted = x;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(n / 2), sorted.end());
    const double median = sorted[n / 2];
    std::vector<char> still(n, 0);
    for (size_t v = 0; v < n; ++v) still[v] = x[v] > median;
    const detail::RepairResult half = thin(&still);
    CHECK(half.thin_tried > 0);
    CHECK(half.thin_tried < plain.thin_tried);
    // A vertex the thinning took away had a neighbour that was not still, or
    // lay beside a contraction (whose fan is a change in turn).
    std::vector<char> kept(n, 0);
    for (long v : half.origin)
      if (v >= 0) kept[static_cast<size_t>(v)] = 1;
    long far_removed = 0, removed = 0;
    for (size_t v = 0; v < n; ++v) {
      if (kept[v]) continue;
      ++removed;
      far_removed += x[v] > median + 5.0;  // Angstrom: several edges into the still half
    }
    CHECK(removed > 0);
    CHECK(far_removed == 0);
  }
}

TEST_CASE("local repair: a patch that would take nearly every vertex is left to the whole-frame remesh", "[morph]") {
  const PeptFrame f = pept_frame();
  const std::vector<char> all_failing(f.mesh.triangles.size(), 1);  // the patch is the whole mesh
  detail::LocalRepairOptions options;
  auto repair = [&] { return detail::repair_locally(f.complex, f.mesh, all_failing, MeshingOptions{}, f.accept, options); };
  CHECK_FALSE(repair().ok);
  options.policy.max_sample_share = 2;  // no bound: the same patch is meshed
  const detail::RepairResult meshed = repair();
  CHECK(meshed.ok);
  CHECK(meshed.counts.patch_triangles == static_cast<long>(f.mesh.triangles.size()));
}

namespace {

// Ubiquitin's atoms from `first` on (the C-terminal strand and what
// precedes it) turned by `degrees` about (1,2,3) through atom `first`;
// each vertex of the mesh at 20 degrees projected onto the new skin from
// where its owning ball took it; the edits first, as a frame's repair does.
// What they leave is for the local patch.
struct TurnedStrand {
  std::vector<Ball> before, after;
  SkinComplex to;
  MeshingOptions accept;
  detail::RepairResult edited;
  detail::LocalRepairOptions options;
};

TurnedStrand turned_strand(size_t first, double degrees) {
  TurnedStrand f;
  f.before = test::centred_model(test::data_file("1ubi.pdb"), 1);
  REQUIRE(f.before.size() > first);
  f.after = f.before;
  const Eigen::Vector3d pivot = f.before[first].center;
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(degrees * M_PI / 180, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  for (size_t i = first; i < f.after.size(); ++i) f.after[i].center = pivot + turn * (f.before[i].center - pivot);
  const SkinComplex from = build_skin_complex(f.before);
  f.to = build_skin_complex(f.after);
  f.accept.min_angle = 20;
  SkinMeshResult made = mesh_skin(from, f.accept);
  REQUIRE(made.status == MeshingStatus::ok);
  SurfaceMesh moved = made.mesh;
  for (size_t v = 0; v < moved.vertices.size(); ++v) {
    const int owner = from.owning_ball(moved.vertices[v], moved.cells[v]);
    const auto b = static_cast<size_t>(owner);
    Eigen::Vector3d offset = moved.vertices[v] - f.before[b].center;
    if (b >= first) offset = turn * offset;
    const Projection p = f.to.project(f.after[b].center + offset, f.to.vertex_cell(owner), 1e-14);
    REQUIRE(p.converged);
    moved.vertices[v] = p.point;
    moved.cells[v] = p.cell;
    moved.normals[v] = f.to.evaluate(p.point, p.cell).gradient.normalized();
  }
  const std::vector<char> failing = detail::failing_triangles(f.to, moved, moved.triangles, f.accept);
  f.edited = detail::mend_by_edits(f.to, moved, failing, f.accept, EditPolicy{});
  REQUIRE(f.edited.left > 0);
  f.options.euler_change = skin_topology(f.after).euler - skin_topology(f.before).euler;
  return f;
}

// The frame a patch made: every triangle passes the frame's criteria, and
// the static mesher's guarantees hold by the independent check (on the skin
// by the oracle, closed oriented manifold, no self-intersections, the
// skin's topology).
void check_patched(const TurnedStrand& f, const detail::RepairResult& patched) {
  const std::vector<char> still = detail::failing_triangles(f.to, patched.mesh, patched.mesh.triangles, f.accept);
  CHECK(std::count(still.begin(), still.end(), 1) == 0);
  GuaranteeOptions guarantees;
  guarantees.min_angle = 20;
  guarantees.on_skin_tolerance = 1e-8;
  const GuaranteeReport report = check_guarantees(patched.mesh, f.after, 0.5, guarantees);
  CHECK(report.all_hold());
}

// The strand's edited mesh patched with one policy setting changed.
template <class T>
detail::RepairResult patched_with(TurnedStrand& f, T PatchPolicy::*setting, T value) {
  f.options.policy.*setting = value;
  return detail::repair_locally(f.to, f.edited.mesh, f.edited.failing, f.accept, f.accept, f.options);
}

// The patch with `setting` at `wider` and at `narrower`: both succeed, the
// narrower takes fewer context vertices an attempt, and its frame holds
// the guarantees.
template <class T>
void fewer_context_with(TurnedStrand& f, T PatchPolicy::*setting, T wider, T narrower) {
  const detail::RepairResult wide = patched_with(f, setting, wider);
  const detail::RepairResult narrow = patched_with(f, setting, narrower);
  REQUIRE(wide.ok);
  REQUIRE(narrow.ok);
  INFO("context vertices: " << narrow.context_vertices << " over " << narrow.attempts << " attempts against "
                            << wide.context_vertices << " over " << wide.attempts);
  CHECK(narrow.context_vertices * wide.attempts < wide.context_vertices * narrow.attempts);
  check_patched(f, narrow);
}

}  // namespace

TEST_CASE("edits: what still fails after them is told by kind, each kind by the mesher's own criteria", "[morph]") {
  // The strand's last 40 atoms turned by 25 degrees: the edits leave
  // triangles failing for the patch.
  const TurnedStrand f = turned_strand(560, 25);
  const detail::FailingKinds kinds = detail::failing_kinds(f.to, f.edited.mesh, f.edited.failing, f.accept);
  long not_restricted = 0, shape = 0, size = 0, inward = 0, passing = 0;
  for (size_t k = 0; k < f.edited.failing.size(); ++k) {
    if (!f.edited.failing[k]) continue;
    const std::array<int, 3>& t = f.edited.mesh.triangles[k];
    const std::array<Eigen::Vector3d, 3> corners{f.edited.mesh.vertices[static_cast<size_t>(t[0])],
                                                 f.edited.mesh.vertices[static_cast<size_t>(t[1])],
                                                 f.edited.mesh.vertices[static_cast<size_t>(t[2])]};
    const auto restricted = restricted_triangle(f.to, corners, f.accept.tolerance, f.edited.mesh.cells[static_cast<size_t>(t[0])]);
    if (!restricted) {
      ++not_restricted;
      continue;
    }
    switch (triangle_defect(f.to, *restricted, f.accept)) {
      case TriangleDefect::none: faces_outward(f.to, *restricted) ? ++passing : ++inward; break;
      case TriangleDefect::shape: ++shape; break;
      case TriangleDefect::size:
      case TriangleDefect::distance: ++size; break;
      case TriangleDefect::topology: ++not_restricted; break;
    }
  }
  INFO(kinds.text());
  CHECK(passing == 0);  // the edits' verdicts are the frame's
  CHECK(kinds.passing == 0);
  CHECK(kinds.not_restricted == not_restricted);
  CHECK(kinds.shape == shape);
  CHECK(kinds.size == size);
  CHECK(kinds.inward == inward);
  CHECK(not_restricted + shape + size + inward == f.edited.left);
  CHECK(kinds.text().rfind("not restricted " + std::to_string(not_restricted) + ", shape " + std::to_string(shape), 0) == 0);
}

TEST_CASE("local repair: after an attempt with faults only the pieces that had them are meshed again", "[morph]") {
  // The strand's last 32 atoms turned by 2 degrees, patched with and
  // without retrying in pieces.
  TurnedStrand f = turned_strand(570, 2);
  f.options.policy.retry_around_faults = false;
  const detail::RepairResult whole = patched_with(f, &PatchPolicy::retry_in_pieces, false);
  const detail::RepairResult pieces = patched_with(f, &PatchPolicy::retry_in_pieces, true);
  REQUIRE(whole.ok);
  REQUIRE(whole.attempts >= 2);  // the frame needs a second attempt
  REQUIRE(pieces.ok);
  CHECK(pieces.failed_because.empty());
  // Later attempts mesh only what had faults: fewer triangles in all.
  CHECK(pieces.attempted_triangles < whole.attempted_triangles);
  check_patched(f, pieces);
  // A kept vertex stays where it was.
  REQUIRE(pieces.origin.size() == pieces.mesh.vertices.size());
  long kept = 0;
  for (size_t v = 0; v < pieces.origin.size(); ++v)
    if (pieces.origin[v] >= 0) {
      ++kept;
      CHECK(pieces.mesh.vertices[v] == f.edited.mesh.vertices[static_cast<size_t>(pieces.origin[v])]);
    }
  CHECK(kept > 0);
}

TEST_CASE("local repair: after an attempt with faults only the triangles around its faults are meshed again",
          "[morph]") {
  // The strand's last 62 atoms turned by 3 degrees (a first region of
  // thousands of triangles), retried in pieces and around the faults.
  // Around the faults, every triangle of the first attempt goes in and the
  // second meshes the fault neighbourhoods only: fewer triangles in all
  // than meshing each faulty piece again.
  TurnedStrand f = turned_strand(540, 3);
  const detail::RepairResult pieces = patched_with(f, &PatchPolicy::retry_around_faults, false);
  const detail::RepairResult around = patched_with(f, &PatchPolicy::retry_around_faults, true);
  REQUIRE(pieces.ok);
  REQUIRE(pieces.attempts >= 2);
  REQUIRE(around.ok);
  REQUIRE(around.attempts >= 2);
  INFO("triangles meshed: around the faults " << around.attempted_triangles << " in " << around.attempts
                                               << " attempts, in pieces " << pieces.attempted_triangles << " in "
                                               << pieces.attempts);
  CHECK(around.attempted_triangles < pieces.attempted_triangles);
  check_patched(f, around);
  REQUIRE(around.origin.size() == around.mesh.vertices.size());
  for (size_t v = 0; v < around.origin.size(); ++v)
    if (around.origin[v] >= 0)
      CHECK(around.mesh.vertices[v] == f.edited.mesh.vertices[static_cast<size_t>(around.origin[v])]);
}

TEST_CASE("local repair: a new point whose star does not close grows the patch over the context near it", "[morph][large]") {
  // The last 42 atoms turned by 25 degrees: a new point near the patch's
  // rim misses triangles whose third corner is context, and growing around
  // the star's own corners never reaches that context.
  TurnedStrand f = turned_strand(560, 25);
  f.options.policy.max_sample_share = 2;  // no bound: the patch may take most of the frame
  const detail::RepairResult corners_only = patched_with(f, &PatchPolicy::open_star_reach, 0.0);
  CHECK_FALSE(corners_only.ok);
  CHECK(corners_only.failed_because.find("seam") != std::string::npos);
  const detail::RepairResult grown = patched_with(f, &PatchPolicy::open_star_reach, PatchPolicy{}.open_star_reach);
  REQUIRE(grown.ok);
  check_patched(f, grown);
}

TEST_CASE("local repair: a patch first takes a context near each of its vertices", "[morph]") {
  // The strand's last 32 atoms turned by 2 degrees (as above). The region's
  // longest edge, the measure of the whole-region context, is longer than
  // its edges near most of its vertices: the local context is smaller, the
  // patch with it succeeds, and the frame it makes holds the guarantees.
  TurnedStrand f = turned_strand(570, 2);
  fewer_context_with(f, &PatchPolicy::local_context_first, false, true);
}

TEST_CASE("local repair: the local context reaches at most local_reach_cap target lengths", "[morph]") {
  // The strand's last 53 atoms turned by 3 degrees: transport stretches
  // region triangles to more than six target lengths, and twice such an
  // edge sets the uncapped reach at the vertices near them. Capped, the
  // patch takes fewer context vertices and still makes a frame that holds
  // the guarantees.
  TurnedStrand f = turned_strand(540, 3);
  f.options.policy.retry_around_faults = true;
  fewer_context_with(f, &PatchPolicy::local_reach_cap, 0.0, 6.0);
}

TEST_CASE("local repair: the context reaches context_reach times the local measure", "[morph]") {
  // The strand's last 53 atoms turned by 3 degrees (as above). With 1.5
  // instead of 2 the patch's Delaunay triangulation takes fewer context
  // vertices an attempt and still makes a frame that holds the guarantees.
  TurnedStrand f = turned_strand(540, 3);
  f.options.policy.retry_around_faults = true;
  f.options.policy.local_reach_cap = 6;
  fewer_context_with(f, &PatchPolicy::context_reach, 2.0, 1.5);
}

TEST_CASE("local repair: a patch that fails is tried once more from the start with wider_rings more rings", "[morph]") {
  SECTION("allowed one attempt a round, the patch fails, and its second round meshes a wider region") {
    // The strand's last 32 atoms turned by 5 degrees need more than one
    // attempt; each round is a local context's attempt and a whole one's.
    TurnedStrand f = turned_strand(570, 5);
    f.options.policy.attempts = 1;
    const detail::RepairResult narrow = patched_with(f, &PatchPolicy::wider_rings, 0);
    REQUIRE_FALSE(narrow.ok);
    const detail::RepairResult wider = patched_with(f, &PatchPolicy::wider_rings, 1);
    CHECK(wider.attempts > narrow.attempts);
    // The first round again, then the same attempts over a region of two
    // rings, which holds the one-ring region and more.
    CHECK(wider.attempted_triangles > 2 * narrow.attempted_triangles);
    if (!wider.ok) CHECK(wider.failed_because.find("with 2 rings") != std::string::npos);
    if (wider.ok) check_patched(f, wider);
  }
  SECTION("a patch that succeeds is not tried again") {
    TurnedStrand f = turned_strand(570, 2);
    const detail::RepairResult narrow = patched_with(f, &PatchPolicy::wider_rings, 0);
    REQUIRE(narrow.ok);
    const detail::RepairResult wider = patched_with(f, &PatchPolicy::wider_rings, 1);
    REQUIRE(wider.ok);
    CHECK(wider.attempts == narrow.attempts);
    CHECK(wider.mesh.triangles == narrow.mesh.triangles);
  }
  SECTION("a patch that took nearly the whole frame is not tried again") {
    TurnedStrand f = turned_strand(500, 4);
    f.options.policy.max_sample_share = 0.3;
    const detail::RepairResult narrow = patched_with(f, &PatchPolicy::wider_rings, 0);
    REQUIRE_FALSE(narrow.ok);
    REQUIRE(narrow.failed_because.find("nearly the whole frame") != std::string::npos);
    CHECK(patched_with(f, &PatchPolicy::wider_rings, 1).attempts == narrow.attempts);
  }
  SECTION("a patch whose seam held with the wrong topology is not tried again") {
    // The strand turned by 2 degrees is patched at the first round; told
    // that the Euler characteristic changes by 2 (it does not), the patch
    // holds at its seam and is refused by the topology check.
    TurnedStrand f = turned_strand(570, 2);
    REQUIRE(patched_with(f, &PatchPolicy::wider_rings, 0).ok);
    f.options.euler_change += 2;
    const detail::RepairResult narrow = patched_with(f, &PatchPolicy::wider_rings, 0);
    REQUIRE_FALSE(narrow.ok);
    REQUIRE(narrow.wrong_topology);
    const detail::RepairResult wider = patched_with(f, &PatchPolicy::wider_rings, 1);
    CHECK_FALSE(wider.ok);
    CHECK(wider.wrong_topology);
    CHECK(wider.attempts == narrow.attempts);
    CHECK(wider.failed_because.find("with 2 rings") == std::string::npos);
  }
}

namespace {

// A closed mesh appended to `mesh`: an octahedron (a sphere, Euler 2) of
// half-diagonal r at c. Returns the index of its first vertex.
int add_octahedron(SurfaceMesh& mesh, const Eigen::Vector3d& c, double r) {
  const int o = static_cast<int>(mesh.vertices.size());
  for (const Eigen::Vector3d& d : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(0, 1, 0),
                                   Eigen::Vector3d(0, -1, 0), Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, -1)}) {
    mesh.vertices.push_back(c + r * d);
    mesh.normals.push_back(d);
    mesh.cells.push_back(0);
  }
  for (const std::array<int, 3>& t : std::vector<std::array<int, 3>>{
           {0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}})
    mesh.triangles.push_back({o + t[0], o + t[1], o + t[2]});
  return o;
}

// A torus (Euler 0) of n x n quads, radii R and r, about the z axis through c.
void add_torus(SurfaceMesh& mesh, const Eigen::Vector3d& c, double R, double r, int n) {
  const int o = static_cast<int>(mesh.vertices.size());
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double u = 2 * M_PI * i / n, v = 2 * M_PI * j / n;
      mesh.vertices.push_back(c + Eigen::Vector3d((R + r * std::cos(v)) * std::cos(u),
                                                  (R + r * std::cos(v)) * std::sin(u), r * std::sin(v)));
      mesh.normals.push_back(Eigen::Vector3d::UnitZ());
      mesh.cells.push_back(0);
    }
  const auto at = [&](int i, int j) { return o + (i % n) * n + (j % n); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
}

std::vector<int> marked(const std::vector<char>& marks) {
  std::vector<int> out;
  for (size_t v = 0; v < marks.size(); ++v)
    if (marks[v]) out.push_back(static_cast<int>(v));
  return out;
}

}  // namespace

TEST_CASE("a vanishing sphere takes the one sphere component wholly within its reach, and nothing else",
          "[morph][events]") {
  // A large sphere, two small ones 3 A apart, a torus, and an unused vertex
  // inside the first small sphere (no triangle uses it).
  SurfaceMesh mesh;
  add_octahedron(mesh, Eigen::Vector3d::Zero(), 10);
  const int small = add_octahedron(mesh, Eigen::Vector3d(20, 0, 0), 1);
  add_octahedron(mesh, Eigen::Vector3d(23, 0, 0), 1);
  add_torus(mesh, Eigen::Vector3d(0, 20, 0), 2, 0.5, 12);
  mesh.vertices.push_back(Eigen::Vector3d(20, 0, 0));
  mesh.normals.push_back(Eigen::Vector3d::UnitZ());
  mesh.cells.push_back(0);
  const std::vector<char> none(mesh.vertices.size(), 0);
  std::vector<int> first_small;
  for (int v = small; v < small + 6; ++v) first_small.push_back(v);
  std::vector<char> found;
  using detail::VanishingSphere;

  SECTION("the small sphere alone within reach is taken, every vertex of it and no other") {
    const std::vector<char> drop = detail::vanishing_components(mesh, none, {{Eigen::Vector3d(20, 0, 0), 1.5}}, found);
    CHECK(found == std::vector<char>{1});
    CHECK(marked(drop) == first_small);
  }
  SECTION("two sphere components within reach: neither is taken") {
    const std::vector<char> drop = detail::vanishing_components(mesh, none, {{Eigen::Vector3d(21.5, 0, 0), 3}}, found);
    CHECK(found == std::vector<char>{0});
    CHECK(marked(drop).empty());
  }
  SECTION("a component a vertex of which stayed in its cell is not taken") {
    std::vector<char> stayed = none;
    stayed[static_cast<size_t>(small + 3)] = 1;
    const std::vector<char> drop =
        detail::vanishing_components(mesh, stayed, {{Eigen::Vector3d(20, 0, 0), 1.5}}, found);
    CHECK(found == std::vector<char>{0});
    CHECK(marked(drop).empty());
  }
  SECTION("a component only partly within reach is not taken, however closed its part within reach looks") {
    // A second octahedron sharing the small one's vertex (21, 0, 0): within
    // 1.05 A of (20, 0, 0) lie the small one's 8 triangles, closed as a
    // sphere, while the component goes on beyond.
    SurfaceMesh pinched = mesh;
    const int shared = small;  // (21, 0, 0)
    const int second = add_octahedron(pinched, Eigen::Vector3d(22, 0, 0), 1);
    for (auto& t : pinched.triangles)
      for (int& v : t)
        if (v == second + 1) v = shared;  // (21, 0, 0) is the second's -x corner
    const std::vector<char> stayed(pinched.vertices.size(), 0);
    const std::vector<char> drop =
        detail::vanishing_components(pinched, stayed, {{Eigen::Vector3d(20, 0, 0), 1.05}}, found);
    CHECK(found == std::vector<char>{0});
    CHECK(marked(drop).empty());
    // Within a reach that holds the whole large sphere, and nothing else, it is taken.
    const std::vector<char> large = detail::vanishing_components(mesh, none, {{Eigen::Vector3d::Zero(), 10.5}}, found);
    CHECK(found == std::vector<char>{1});
    CHECK(marked(large) == std::vector<int>{0, 1, 2, 3, 4, 5});
  }
  SECTION("a component that is not a sphere is not taken") {
    const std::vector<char> drop = detail::vanishing_components(mesh, none, {{Eigen::Vector3d(0, 20, 0), 3}}, found);
    CHECK(found == std::vector<char>{0});
    CHECK(marked(drop).empty());
  }
  SECTION("a component is taken by one sphere only") {
    const std::vector<char> drop = detail::vanishing_components(
        mesh, none, {{Eigen::Vector3d(20, 0, 0), 1.5}, {Eigen::Vector3d(20.2, 0, 0), 1.5}}, found);
    CHECK(found == std::vector<char>{1, 0});
    CHECK(marked(drop) == first_small);
  }
  SECTION("each sphere takes its own") {
    const std::vector<char> drop = detail::vanishing_components(
        mesh, none, {{Eigen::Vector3d(23, 0, 0), 1.5}, {Eigen::Vector3d(20, 0, 0), 1.5}}, found);
    CHECK(found == std::vector<char>{1, 1});
    std::vector<int> both = first_small;
    for (int v = small + 6; v < small + 12; ++v) both.push_back(v);
    CHECK(marked(drop) == both);
  }
}

TEST_CASE("lost vertices: each merged into a neighbour, the mesh a closed oriented manifold of the same topology",
          "[morph]") {
  const PeptFrame f = pept_frame();
  const SurfaceMesh& mesh = f.mesh;
  const size_t n = mesh.vertices.size();
  // Scattered lost vertices, and one with its whole ring lost (whose
  // neighbours must go first, into vertices that are not lost).
  std::vector<char> lost(n, 0);
  for (size_t v = 7; v < n; v += n / 9) lost[v] = 1;
  const int centre = static_cast<int>(n / 2);
  lost[static_cast<size_t>(centre)] = 1;
  for (const auto& t : mesh.triangles)
    if (std::find(t.begin(), t.end(), centre) != t.end())
      for (int v : t) lost[static_cast<size_t>(v)] = 1;
  const long marked = std::count(lost.begin(), lost.end(), 1);
  REQUIRE(marked > 12);

  SurfaceMesh merged = mesh;
  std::vector<char> marks = lost;
  std::vector<int> kept_from;
  std::vector<char> touched;
  REQUIRE(detail::merge_lost_vertices(merged, marks, kept_from, touched));
  CHECK(std::count(marks.begin(), marks.end(), 1) == 0);
  REQUIRE(merged.vertices.size() == n - static_cast<size_t>(marked));
  CHECK(merged.triangles.size() == mesh.triangles.size() - 2 * static_cast<size_t>(marked));
  REQUIRE(kept_from.size() == merged.vertices.size());
  REQUIRE(touched.size() == merged.vertices.size());
  for (size_t k = 0; k < kept_from.size(); ++k) {
    REQUIRE(!lost[static_cast<size_t>(kept_from[k])]);
    CHECK(merged.vertices[k] == mesh.vertices[static_cast<size_t>(kept_from[k])]);  // nothing moved
  }
  const MeshQuality before = grade_mesh(mesh), after = grade_mesh(merged);
  CHECK((after.closed && after.manifold && after.oriented));
  CHECK(mesh_topology(merged) == mesh_topology(mesh));
  CHECK(after.euler == before.euler);
  // A triangle that is not one of the mesh's own (by its corners' old
  // numbers) has every corner marked touched.
  std::set<std::array<int, 3>> own;
  for (auto t : mesh.triangles) {
    std::sort(t.begin(), t.end());
    own.insert(t);
  }
  long changed = 0;
  for (const auto& t : merged.triangles) {
    std::array<int, 3> old{kept_from[static_cast<size_t>(t[0])], kept_from[static_cast<size_t>(t[1])],
                           kept_from[static_cast<size_t>(t[2])]};
    std::sort(old.begin(), old.end());
    if (own.count(old)) continue;
    ++changed;
    for (int v : t) CHECK(touched[static_cast<size_t>(v)]);
  }
  CHECK(changed >= marked);

  SECTION("a vertex whose merge would break the link condition everywhere stays: false, nothing changed") {
    // A tetrahedron: every contraction leaves two triangles on three points.
    SurfaceMesh tetrahedron;
    tetrahedron.vertices = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0),
                            Eigen::Vector3d(0, 0, 1)};
    tetrahedron.cells = {0, 0, 0, 0};
    tetrahedron.normals.assign(4, Eigen::Vector3d::UnitZ());
    tetrahedron.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    const SurfaceMesh given = tetrahedron;
    std::vector<char> one_lost{1, 0, 0, 0};
    CHECK_FALSE(detail::merge_lost_vertices(tetrahedron, one_lost, kept_from, touched));
    CHECK(tetrahedron.triangles == given.triangles);
    CHECK(one_lost == std::vector<char>{1, 0, 0, 0});
  }
}

namespace {

detail::TopologyChange birth_in(const SkinComplex& complex, int cell) {
  detail::TopologyChange change;
  change.birth = true;
  change.cell = cell;
  change.dim = complex.cell(cell).dim;
  change.point = complex.cell(cell).center;
  change.euler_change = 2;
  return change;
}

// A born sphere against references that do not use it: every vertex on the
// skin by the QP oracle, a closed oriented manifold of one component with
// the Euler characteristic of a sphere, every triangle passing the judge,
// facing as the skin's gradient, and the enclosed volume's sign.
void check_born_sphere(const SkinComplex& complex, const SurfaceMesh& m, const MeshingOptions& criteria, bool is_void) {
  const SkinOracle oracle(complex.balls(), complex.shrink());
  double worst = 0;
  for (const Eigen::Vector3d& x : m.vertices) worst = std::max(worst, oracle.evaluate(x).distance());
  CHECK(worst < 1e-12);
  const MeshQuality q = grade_mesh(m);
  CHECK(q.closed);
  CHECK(q.manifold);
  CHECK(q.oriented);
  CHECK(q.components == 1);
  CHECK(q.euler == 2);
  CHECK(q.min_angle >= criteria.min_angle);
  const SurfaceComponents parts = surface_components(m);
  REQUIRE(parts.enclosed_volume.size() == 1);
  CHECK((parts.enclosed_volume[0] < 0) == is_void);
  for (const auto& t : m.triangles) {
    const std::array<Eigen::Vector3d, 3> corners{m.vertices[static_cast<size_t>(t[0])], m.vertices[static_cast<size_t>(t[1])],
                                                 m.vertices[static_cast<size_t>(t[2])]};
    CHECK(detail::triangle_passes(complex, corners, m.cells[static_cast<size_t>(t[0])], criteria));
  }
}

}  // namespace

TEST_CASE("births: a component's and a void's sphere meshed on the skin, every triangle passing", "[morph]") {
  const MeshingOptions criteria = MovingOptions{}.frames;
  SECTION("a component: a lone ball's sphere, facing out") {
    const SkinComplex lone = build_skin_complex({{Eigen::Vector3d(1, 2, 3), 1.7 * 1.7}});
    const std::optional<SurfaceMesh> m = detail::born_sphere(lone, birth_in(lone, 0), criteria);
    REQUIRE(m);
    check_born_sphere(lone, *m, criteria, false);
    CHECK(m->triangles.size() == 320);  // radius 1.2 A: two splits of the icosahedron pass the frames' criteria
  }
  SECTION("a void: the sphere in the tetrahedron of four balls, facing in") {
    const SkinComplex four = build_skin_complex(test::tetrahedron_of_balls(2.5));
    REQUIRE(skin_topology(four.balls()).voids == 1);  // premise: one void
    long made = 0;
    for (int c = 0; c < static_cast<int>(four.cells().size()); ++c) {
      if (four.cell(c).dim != 3) continue;
      const std::optional<SurfaceMesh> m = detail::born_sphere(four, birth_in(four, c), criteria);
      REQUIRE(m);
      check_born_sphere(four, *m, criteria, true);
      ++made;
    }
    CHECK(made == 1);
    // Past the cell's inradius the void's skin is no longer one sphere.
    const SkinComplex wide = build_skin_complex(test::tetrahedron_of_balls(2.6));
    for (int c = 0; c < static_cast<int>(wide.cells().size()); ++c)
      if (wide.cell(c).dim == 3) CHECK_FALSE(detail::born_sphere(wide, birth_in(wide, c), criteria));
  }
  SECTION("a sphere the cell cuts: the skin there is not the sphere") {
    // Two balls overlapping: each vertex cell holds only part of its ball's sphere.
    const SkinComplex two = build_skin_complex({{Eigen::Vector3d(0, 0, 0), 2.25}, {Eigen::Vector3d(2, 0, 0), 2.25}});
    for (int c = 0; c < static_cast<int>(two.cells().size()); ++c)
      if (two.cell(c).dim == 0) CHECK_FALSE(detail::born_sphere(two, birth_in(two, c), criteria));
  }
  SECTION("added to a frame as a component of its own, but not where a vertex lies on it already") {
    const SkinComplex lone = build_skin_complex({{Eigen::Vector3d(1, 2, 3), 1.7 * 1.7}});
    const std::vector<detail::TopologyChange> changes{birth_in(lone, 0)};
    SurfaceMesh empty;
    detail::RepairResult r;
    std::vector<char> done;
    CHECK(detail::add_born_spheres(lone, empty, {}, changes, criteria, r, done) == 1);
    REQUIRE(r.ok);
    CHECK(done == std::vector<char>{1});
    CHECK(r.mesh.cells.size() == r.mesh.vertices.size());
    CHECK(r.failing == std::vector<char>(r.mesh.triangles.size(), 0));
    CHECK(std::count(r.origin.begin(), r.origin.end(), -1) == static_cast<long>(r.mesh.vertices.size()));
    // A second time over the mesh just made: its vertices lie in the cell.
    detail::RepairResult again;
    std::vector<char> done_again;
    CHECK(detail::add_born_spheres(lone, r.mesh, r.failing, changes, criteria, again, done_again) == 0);
    CHECK_FALSE(again.ok);
    CHECK(done_again == std::vector<char>{0});
  }
  SECTION("not a birth, or not a vertex or tetrahedron") {
    const SkinComplex lone = build_skin_complex({{Eigen::Vector3d(1, 2, 3), 1.7 * 1.7}});
    detail::TopologyChange change = birth_in(lone, 0);
    change.birth = false;
    CHECK_FALSE(detail::born_sphere(lone, change, criteria));
  }
}
