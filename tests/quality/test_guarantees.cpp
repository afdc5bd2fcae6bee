// The guarantee check: each guarantee fails on a mesh built to break it and
// only it, and all hold on the mesher's own mesh. On-skin distances come from
// the oracle (docs/math.md section 2), never from the mixed complex.
#include "test_support.hpp"

#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/quality/guarantees.hpp"

#include <catch2/catch.hpp>

using namespace skinmesh;

TEST_CASE("check_guarantees: all hold on the mesher's mesh, each fails where broken", "[quality][guarantees][large]") {
  const auto balls = balls_from_molecule(read_molecule(test::data_file("pept.pdb")), 0.5);
  const SkinMeshResult r = mesh_skin(build_skin_complex(balls, {0.5}));
  REQUIRE(r.status == MeshingStatus::ok);
  const GuaranteeReport good = check_guarantees(r.mesh, balls, 0.5);
  CHECK(good.all_hold());
  CHECK(good.topology == std::optional<bool>(true));
  CHECK(good.surface_error.max <= 1e-9);
  CHECK(good.quality.min_angle >= 30.0 - 1e-9);

  SECTION("a vertex 0.01 A off the skin") {
    SurfaceMesh moved = r.mesh;
    moved.vertices[0] += 0.01 * moved.normals[0];
    const GuaranteeReport g = check_guarantees(moved, balls, 0.5);
    CHECK_FALSE(g.on_skin);
    CHECK(g.surface_error.max == Approx(0.01).epsilon(0.05));
    CHECK(g.closed_oriented_manifold);
    CHECK_FALSE(g.all_hold());
  }
  SECTION("a triangle turned inside out") {
    SurfaceMesh flipped = r.mesh;
    std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);
    const GuaranteeReport g = check_guarantees(flipped, balls, 0.5);
    CHECK_FALSE(g.closed_oriented_manifold);
    CHECK(g.on_skin);
    CHECK_FALSE(g.all_hold());
  }
  SECTION("a hole") {
    SurfaceMesh open = r.mesh;
    open.triangles.pop_back();
    CHECK_FALSE(check_guarantees(open, balls, 0.5).closed_oriented_manifold);
  }
  SECTION("a bound the mesh does not meet") {
    GuaranteeOptions stricter;
    stricter.min_angle = good.quality.min_angle + 0.5;
    const GuaranteeReport g = check_guarantees(r.mesh, balls, 0.5, stricter);
    CHECK_FALSE(g.angle);
    CHECK(g.on_skin);
  }
  SECTION("a skin with a second component the mesh lacks") {
    std::vector<Ball> more = balls;  // a ball 100 A off: the skin near pept is unchanged
    more.push_back(Ball{balls[0].center + Eigen::Vector3d(100, 0, 0), 4.0});
    const GuaranteeReport g = check_guarantees(r.mesh, more, 0.5);
    REQUIRE(g.skin.has_value());
    CHECK(g.skin->components == good.skin->components + 1);
    CHECK(g.topology == std::optional<bool>(false));
    CHECK(g.on_skin);
    CHECK(g.closed_oriented_manifold);
    CHECK_FALSE(g.all_hold());
    GuaranteeOptions no_topology;
    no_topology.topology = false;
    const GuaranteeReport skipped = check_guarantees(r.mesh, more, 0.5, no_topology);
    CHECK_FALSE(skipped.topology.has_value());
    CHECK(skipped.all_hold());
  }
  SECTION("the skin given by another oracle: its distances, and the complex where it does not certify") {
    SkinReference skin{balls, 0.5, [](const Eigen::Vector3d&, const OracleStart&) { return SkinDistance{0.02, true}; }, {}, {}};
    const GuaranteeReport off = check_guarantees(r.mesh, skin);
    CHECK(off.surface_error.max == 0.02);
    CHECK_FALSE(off.on_skin);
    skin.oracle = [](const Eigen::Vector3d&, const OracleStart&) { return SkinDistance{5.0, false}; };
    const GuaranteeReport measured = check_guarantees(r.mesh, skin);
    CHECK(measured.surface_error.uncertified == static_cast<long>(r.mesh.vertices.size()));
    CHECK(measured.surface_error.max <= 1e-9);  // on the complex built from scratch, not the oracle's 5 A
    CHECK(measured.all_hold());
  }
  SECTION("the skin's topology as the caller counted it, not counted again") {
    SkinReference skin{balls, 0.5, {}, {}, good.skin};
    CHECK(check_guarantees(r.mesh, skin).topology == std::optional<bool>(true));
    SkinTopology wrong = *good.skin;
    wrong.euler += 2;
    skin.topology = wrong;
    const GuaranteeReport g = check_guarantees(r.mesh, skin);
    CHECK(g.skin == std::optional<SkinTopology>(wrong));
    CHECK(g.topology == std::optional<bool>(false));
  }
  SECTION("the self-intersection check skipped is reported as not made") {
    GuaranteeOptions skip;
    skip.self_intersections = SelfIntersectionCheck::skip;
    const GuaranteeReport g = check_guarantees(r.mesh, balls, 0.5, skip);
    CHECK_FALSE(g.no_self_intersections.has_value());
    CHECK(g.all_hold());
  }
}

TEST_CASE("check_guarantees: two interpenetrating tetrahedra intersect", "[quality][guarantees]") {
  const SurfaceMesh two = test::two_interpenetrating_tetrahedra();
  // One ball whose skin the corners are nowhere near: only the topology is asked about here.
  const GuaranteeReport g = check_guarantees(two, {Ball{Eigen::Vector3d::Zero(), 1.0}}, 0.5);
  CHECK(g.closed_oriented_manifold);
  CHECK(g.no_self_intersections == std::optional<bool>(false));
  CHECK_FALSE(g.on_skin);
}

// An earlier frame's oracle answers stand where no ball near the vertex
// changed (GuaranteeOptions::earlier); everywhere the check keeps one, the
// oracle asked afresh gives the same distance, and where the balls moved
// the distance is the new one, not the kept one.
TEST_CASE("check_guarantees: earlier oracle answers are kept only where no near ball changed", "[quality][guarantees]") {
  const auto balls = balls_from_molecule(read_molecule(test::data_file("pept.pdb")), 0.5);
  const SkinMeshResult r = mesh_skin(build_skin_complex(balls, {0.5}));
  REQUIRE(r.status == MeshingStatus::ok);
  GuaranteeOptions report;
  report.report_distances = true;
  CHECK(check_guarantees(r.mesh, balls, 0.5).distances.empty());
  const GuaranteeReport first = check_guarantees(r.mesh, balls, 0.5, report);
  REQUIRE(first.distances.size() == r.mesh.vertices.size());
  const OracleAnswers earlier{balls, 0.5, r.mesh.vertices, first.distances};
  GuaranteeOptions keep = report;
  keep.earlier = &earlier;
  // The atoms on one side of the middle moved 0.3 A along x.
  std::vector<double> xs;
  for (const Ball& b : balls) xs.push_back(b.center.x());
  std::nth_element(xs.begin(), xs.begin() + static_cast<long>(xs.size() / 2), xs.end());
  const double middle = xs[xs.size() / 2];
  std::vector<Ball> moved = balls;
  for (Ball& b : moved)
    if (b.center.x() > middle) b.center.x() += 0.3;
  const auto same_as_asked_afresh = [&](const SurfaceMesh& mesh, const std::vector<Ball>& now) {
    const GuaranteeReport kept = check_guarantees(mesh, now, 0.5, keep);
    const GuaranteeReport fresh = check_guarantees(mesh, now, 0.5, report);
    REQUIRE(kept.distances.size() == fresh.distances.size());
    double worst = 0;
    for (size_t v = 0; v < kept.distances.size(); ++v)
      worst = std::max(worst, std::abs(kept.distances[v].distance - fresh.distances[v].distance));
    CHECK(worst <= 1e-12);
    CHECK(kept.surface_error.max == Approx(fresh.surface_error.max).margin(1e-12));
    CHECK(kept.on_skin == fresh.on_skin);
    return kept;
  };
  SECTION("the same balls: every answer stands") {
    const GuaranteeReport g = same_as_asked_afresh(r.mesh, balls);
    CHECK(g.distances_kept == static_cast<long>(r.mesh.vertices.size()));
  }
  SECTION("half the atoms moved: the far half's answers stand, the mesh is off the moved skin") {
    const GuaranteeReport g = same_as_asked_afresh(r.mesh, moved);
    CHECK(g.distances_kept > 0);
    CHECK(g.distances_kept < static_cast<long>(r.mesh.vertices.size()) / 2 + 1);
    CHECK(g.surface_error.max > 0.1);
    CHECK_FALSE(g.on_skin);
  }
  SECTION("a vertex moved: its answer is asked again") {
    SurfaceMesh shifted = r.mesh;
    shifted.vertices[0] += 0.01 * shifted.normals[0];
    const GuaranteeReport g = same_as_asked_afresh(shifted, balls);
    CHECK(g.distances_kept == static_cast<long>(r.mesh.vertices.size()) - 1);
    CHECK(g.surface_error.max == Approx(0.01).epsilon(0.05));
  }
  SECTION("a ball made heavier, or one more ball: nothing stands") {
    std::vector<Ball> heavier = balls;
    heavier[0].weight = 1.5 * std::max_element(balls.begin(), balls.end(), [](const Ball& a, const Ball& b) {
                                return a.weight < b.weight;
                              })->weight;
    CHECK(same_as_asked_afresh(r.mesh, heavier).distances_kept == 0);
    std::vector<Ball> more = balls;
    more.push_back(Ball{balls[0].center + Eigen::Vector3d(100, 0, 0), 4.0});
    CHECK(same_as_asked_afresh(r.mesh, more).distances_kept == 0);
  }
}
