// The morph in small steps: two balls whose skins join, transported
// frame by frame (most frames kept by transport alone) and repaired where
// the neck forms; every frame checked against the morph oracle, the
// angle bound and the grader; ids kept by surviving vertices and never
// reused. The acceptance tests on real pairs: test_morph_pairs.cpp.
#include "test_support.hpp"
#include "same_frames.hpp"
#include "blend_events.hpp"
#include "two_balls.hpp"

#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/skin_oracle.hpp"
#include "skinmesh/core/skin_topology.hpp"
#include "skinmesh/morph/morph.hpp"
#include "skinmesh/morph/moving_balls.hpp"
#include "skinmesh/quality/mesh_quality.hpp"

#include <catch2/catch.hpp>

#include <set>

using namespace skinmesh;

namespace {

// Ids: unique in the frame; a vertex of the previous frame that survives
// keeps its id; every other id is new (never seen in any earlier frame); the
// frame's counts of inserted and removed vertices match.
void check_ids(const std::vector<long>& before, const MorphFrame& f, std::set<long>& seen) {
  const std::set<long> now(f.ids.begin(), f.ids.end());
  CHECK(now.size() == f.ids.size());
  const std::set<long> previous(before.begin(), before.end());
  long kept = 0;
  for (long id : now) {
    if (previous.count(id)) ++kept;
    else CHECK(seen.count(id) == 0);
  }
  CHECK(static_cast<long>(now.size()) - kept == f.stats.inserted);
  CHECK(static_cast<long>(previous.size()) - kept == f.stats.removed);
  if (!f.stats.repaired && !f.stats.full_rebuild) CHECK(f.ids == before);
  seen.insert(now.begin(), now.end());
}

// Where the frame's time went: stages that do not overlap, within the
// frame's seconds; a frame transported in the overlay was judged (and
// relaxed, when asked), and one kept as transported was not mended.
void check_stage_seconds(const FrameStats& s, const MorphOptions& options) {
  const double stages = s.seconds_complex + s.seconds_transport + s.seconds_relax + s.seconds_judge + s.seconds_repair;
  for (double part : {s.seconds_complex, s.seconds_transport, s.seconds_relax, s.seconds_judge, s.seconds_repair})
    CHECK(part >= 0);
  CHECK(stages <= s.seconds);
  CHECK(s.seconds_transport > 0);
  if (s.lost == 0) {
    CHECK(s.seconds_judge > 0);
    CHECK((s.seconds_relax > 0) == (options.relaxation.passes > 0));
  }
  if (!s.repaired && !s.full_rebuild) CHECK(s.seconds_repair == 0);
  if (s.repaired) CHECK(s.seconds_repair > 0);
  // The edits and the patches are parts of the repair; a patch tried took time.
  CHECK(s.seconds_edits >= 0);
  CHECK(s.seconds_patch >= 0);
  CHECK(s.seconds_edits + s.seconds_patch <= s.seconds_repair);
  CHECK((s.patch_attempts > 0) == (s.seconds_patch > 0));
  if (s.patch_triangles > 0) CHECK(s.patch_attempts > 0);
}

}  // namespace

TEST_CASE("morph frames of two balls: transported until their skins join, repaired there", "[morph][frames]") {
  const test::TwoBallMorph two;
  MorphOptions options;
  Morph morph = prepare_morph(two.source, two.target, 0.05, options);
  const MorphOracle oracle(two.source, two.target, 0.5);
  REQUIRE_FALSE(morph.events().empty());
  const double event = morph.events().front().t;
  long transported = 0;
  std::set<long> seen(morph.frame().ids.begin(), morph.frame().ids.end());
  for (double t = 0.1; t < 0.96; t += 0.05) {
    INFO("t = " << t << ", first event at " << event);
    const std::vector<long> before = morph.frame().ids;
    const MorphFrame& f = morph.advance_to(t);
    double worst = 0;
    for (const Eigen::Vector3d& v : f.mesh.vertices) worst = std::max(worst, oracle.evaluate(v, t).distance());
    CHECK(worst <= 1e-8);
    const MeshQuality q = grade_mesh(f.mesh);
    CHECK(q.min_angle >= options.frames.min_angle - 1e-9);
    CHECK((q.closed && q.manifold && q.oriented && q.self_intersecting_pairs == 0));
    CHECK(q.components == (two.joined(oracle, t, 200) ? 1 : 2));
    transported += !f.stats.repaired && !f.stats.full_rebuild;
    if (f.stats.events > 0) CHECK(f.stats.repaired);
    CHECK_FALSE(f.stats.full_rebuild);
    check_ids(before, f, seen);
    check_stage_seconds(f.stats, options);
  }
  INFO(transported << " of 18 frames transported");
  CHECK(transported > 0);
}

TEST_CASE("advance_to with the next frame announced makes the same frames, also when another frame follows",
          "[morph]") {
  const auto source = test::centred_model(test::data_file("2k39_3models.pdb"), 1);
  const auto target = test::centred_model(test::data_file("2k39_3models.pdb"), 3);
  Morph plain = prepare_morph(source, target, 0.01);
  Morph ahead = prepare_morph(source, target, 0.01);
  long mended_without_remesh = 0;
  for (int k = 2; k <= 16; ++k) {
    const double t = 0.01 * k;
    // Frame 0.08 announces 0.5, and 0.09 follows: the complex moved ahead
    // is not the one asked for, and must not be used.
    const double announced = k == 8 ? 0.5 : 0.01 * (k + 1);
    INFO("t = " << t);
    const MorphFrame& a = plain.advance_to(t);
    const MorphFrame& b = ahead.advance_to(t, announced);
    test::check_same_frames(a, b);
    mended_without_remesh += b.stats.repaired && !b.stats.remeshed;
  }
  CHECK(mended_without_remesh > 0);  // the moving ahead overlapped edits or a patch
}

TEST_CASE("a void sealed and filled within one step is mended locally, with the skin's topology", "[morph][events][large]") {
  const auto source = test::centred_model(test::data_file("pept.pdb"), 1);
  const auto target = test::centred_model(test::data_file("3al1.pdb"), 1);
  test::BlendEvents blend(source, target);
  const std::vector<TopologyEvent>& events = blend.with_critical(source, target).critical;
  const std::vector<CellSize>& sizes = blend.sizes;
  // Steps just around a pair (cancelling_partners) with no other event near.
  constexpr double kMargin = 1e-4;
  std::vector<std::pair<double, double>> steps;
  for (int k = 0; k < 100 && steps.size() < 3; ++k) {
    const std::vector<int> partner =
        cancelling_partners(events, sizes, k / 100.0, (k + 1) / 100.0, std::vector<char>(events.size(), 0));
    for (size_t i = 0; i < events.size() && steps.size() < 3; ++i) {
      if (partner[i] < 0 || events[i].dim != 3) continue;
      const double from = events[static_cast<size_t>(partner[i])].t - kMargin, to = events[i].t + kMargin;
      const long near = std::count_if(events.begin(), events.end(), [&](const TopologyEvent& e) {
        return e.t > from - kMargin && e.t <= to + kMargin;
      });
      if (near == 2) steps.emplace_back(from, to);
    }
  }
  REQUIRE(steps.size() >= 2);  // premise: pept -> 3al1 has such voids
  for (const auto& [from, to] : steps) {
    INFO("step " << from << " .. " << to);
    Morph morph = prepare_morph(source, target, from);
    const MorphFrame& f = morph.advance_to(to);
    CHECK(f.stats.events == 2);
    CHECK(f.stats.remeshed_because.find("vanished") == std::string::npos);
    CHECK(mesh_topology(f.mesh) == skin_topology(interpolated_balls(source, target, blend.live, to)));
  }
}

// A closed tetrahedron 100 A away from everything, outward, with new ids:
// one component more than the skin has.
void add_a_component(SurfaceMesh& mesh, std::vector<long>& ids) {
  const int n = static_cast<int>(mesh.vertices.size());
  const Eigen::Vector3d c(100, 0, 0);
  for (const Eigen::Vector3d& d : {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, -1, -1), Eigen::Vector3d(-1, 1, -1),
                                   Eigen::Vector3d(-1, -1, 1)}) {
    mesh.vertices.push_back(c + d);
    mesh.normals.push_back(d.normalized());
    mesh.cells.push_back(mesh.cells.front());
    ids.push_back(-1 - static_cast<long>(ids.size()));
  }
  for (const std::array<int, 3>& t : {std::array<int, 3>{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}})
    mesh.triangles.push_back({n + t[0], n + t[1], n + t[2]});
}

TEST_CASE("a blend frame remeshed whole is certified against the skin's topology", "[morph][topology]") {
  const test::TwoBallMorph two;
  MorphOptions options;  // every repair a whole-frame remesh
  options.repair.patch.max_failing_share = 0;
  options.repair.patch.always_patch_up_to = 0;
  options.repair.edits.enabled = false;
  Morph morph = prepare_morph(two.source, two.target, 0.05, options);
  int faults = 0;
  // The first frame remeshed whole: with the fault once, its remesh (one
  // component too many) is meshed again from scratch; with the fault always,
  // the frame is refused.
  const auto first_remeshed = [&]() -> const MorphFrame* {
    for (double t = 0.1; t < 0.96; t += 0.05) {
      const MorphFrame& f = morph.advance_to(t);
      if (faults > 0) return &f;
    }
    return nullptr;
  };
  SECTION("a remesh with a component the skin lacks is meshed from scratch") {
    detail::inject_remesh_fault(morph, [&](SurfaceMesh& mesh, std::vector<long>& ids) {
      if (faults++ == 0) add_a_component(mesh, ids);
    });
    const MorphFrame* f = first_remeshed();
    REQUIRE(f != nullptr);
    CHECK(faults == 2);  // the remesh, then the mesh from scratch
    CHECK(mesh_topology(f->mesh) == skin_topology(morph.complex().balls()));
    CHECK(f->stats.full_rebuild);
    CHECK(f->stats.remeshed_because.find("so the frame was meshed from scratch") != std::string::npos);
    CHECK(f->ids.size() == f->mesh.vertices.size());
  }
  SECTION("a frame whose mesh from scratch is wrong too is refused") {
    detail::inject_remesh_fault(morph, [&](SurfaceMesh& mesh, std::vector<long>& ids) {
      ++faults;
      add_a_component(mesh, ids);
    });
    CHECK_THROWS_WITH(first_remeshed(), Catch::Contains("the frame is refused"));
    CHECK(faults == 2);
  }
}
