// Frames of a morph without a regular triangulation, and transport of skin
// points between them (docs/math.md section 4, eq. 19), checked against the
// morph oracle, which knows neither the complex nor the live pairs.
#include "test_support.hpp"
#include "two_balls.hpp"

#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_oracle.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/morph/morph.hpp"
#include "skinmesh/morph/relaxation.hpp"
#include "skinmesh/morph/transport.hpp"
#include "judge.hpp"

#include <tbb/task_arena.h>

#include <catch2/catch.hpp>

#include <random>

using namespace skinmesh;

namespace {

struct MorphPair {
  std::string name;
  std::vector<Ball> source, target;
};

std::vector<MorphPair> morph_pairs() {
  return {{"2k39 model 1 -> 2", test::centred_model(test::data_file("2k39_3models.pdb"), 1),
           test::centred_model(test::data_file("2k39_3models.pdb"), 2)},
          {"pept -> 3al1", test::centred_model(test::data_file("pept.pdb"), 1),
           test::centred_model(test::data_file("3al1.pdb"), 1)}};
}

// The complex of B(t), moved from the one built at t = 1/2.
SkinComplex frame(const SkinComplex& middle, const MorphPair& m, const std::vector<BallPair>& live, double t) {
  return middle.with_balls(interpolated_balls(m.source, m.target, live, t));
}

}  // namespace

TEST_CASE("a frame's complex moved from another has the frame's skin function", "[morph]") {
  for (const MorphPair& m : morph_pairs()) {
    INFO(m.name);
    const std::vector<BallPair> live = live_pairs(m.source, m.target);
    const SkinComplex middle = build_skin_complex(interpolated_balls(m.source, m.target, live, 0.5), {0.5});
    const MorphOracle oracle(m.source, m.target, 0.5);
    std::mt19937 rng(4);
    std::uniform_int_distribution<size_t> pick(0, m.source.size() - 1);
    std::uniform_real_distribution<double> u(-2.5, 2.5);
    for (double t : {0.05, 0.3, 0.7, 0.95}) {
      INFO("t = " << t);
      const SkinComplex moved = frame(middle, m, live, t);
      CHECK(moved.same_flat_cells(middle));
      int hint = -1;
      for (int k = 0; k < 600; ++k) {
        const Eigen::Vector3d x = m.source[pick(rng)].center + Eigen::Vector3d(u(rng), u(rng), u(rng));
        const MorphOracleResult o = oracle.evaluate(x, t);
        REQUIRE(o.certified);
        const SkinEval e = moved.evaluate(x, hint);
        hint = e.cell;
        CHECK(std::abs(e.value - o.value) <= 1e-9 * std::max(1.0, std::abs(o.value)));
      }
    }
  }
}

// Walks from a neighbouring cell are what transport and the mesher's
// crossings do. On B(t) some cells have (numerically) zero size, and a walk
// through one can go round in a cycle; wherever it starts, the cell found
// must hold the point.
TEST_CASE("a walk from any neighbouring cell of a frame's complex ends in a cell holding the point", "[morph]") {
  for (const MorphPair& m : morph_pairs()) {
    INFO(m.name);
    const std::vector<BallPair> live = live_pairs(m.source, m.target);
    const SkinComplex middle = build_skin_complex(interpolated_balls(m.source, m.target, live, 0.5), {0.5});
    const SkinComplex moved = frame(middle, m, live, 0.3);
    const SkinMeshResult mesh = mesh_skin(moved);
    REQUIRE(mesh.status == MeshingStatus::ok);
    long walks = 0, failed = 0;
    for (size_t v = 0; v < mesh.mesh.vertices.size(); v += 3) {
      const Eigen::Vector3d& x = mesh.mesh.vertices[v];
      const int home = mesh.mesh.cells[v];
      std::vector<int> starts(moved.faces_begin(home), moved.faces_end(home));
      for (auto it = moved.cofaces_begin(home); it != moved.cofaces_end(home); ++it) starts.push_back(it->cell);
      for (int start : starts) {
        ++walks;
        failed += moved.membership_violation(moved.locate(x, start), x) > 1e-9;
      }
    }
    INFO(walks << " walks");
    CHECK(walks > 1000);
    CHECK(failed == 0);
  }
}

TEST_CASE("transport puts a skin point that stays in its cell on the next frame's skin", "[morph]") {
  for (const MorphPair& m : morph_pairs()) {
    INFO(m.name);
    const std::vector<BallPair> live = live_pairs(m.source, m.target);
    const SkinComplex middle = build_skin_complex(interpolated_balls(m.source, m.target, live, 0.5), {0.5});
    const SkinComplex at = frame(middle, m, live, 0.3), next = frame(middle, m, live, 0.32);
    const SkinMeshResult mesh = mesh_skin(at);
    REQUIRE(mesh.status == MeshingStatus::ok);
    const MorphOracle oracle(m.source, m.target, 0.5);
    long stayed = 0, left = 0, vanished = 0;
    double worst = 0, worst_before = 0;
    for (size_t v = 0; v < mesh.mesh.vertices.size(); ++v) {
      const Eigen::Vector3d& p = mesh.mesh.vertices[v];
      worst_before = std::max(worst_before, oracle.evaluate(p, 0.3).distance());
      const TransportedPoint moved = transport(at, next, mesh.mesh.cells[v], p);
      if (moved.status == TransportStatus::left_cell) ++left;
      if (moved.status == TransportStatus::size_vanished) ++vanished;
      if (moved.status != TransportStatus::in_cell) continue;
      ++stayed;
      const MorphOracleResult o = oracle.evaluate(moved.point, 0.32);
      REQUIRE(o.certified);
      worst = std::max(worst, o.distance());
    }
    INFO(stayed << " stayed in their cell, " << left << " left it, " << vanished << " in cells whose size vanished");
    CHECK(worst_before <= 1e-9);
    CHECK(worst <= 1e-9);
    CHECK(stayed > 0.5 * static_cast<double>(mesh.mesh.vertices.size()));
  }
}

TEST_CASE("transport reports the cells where a neck forms between two frames", "[morph]") {
  const test::TwoBallMorph two;
  const std::vector<Ball>& source = two.source;
  const std::vector<Ball>& target = two.target;
  const MorphOracle oracle(source, target, 0.5);
  auto joined = [&](double t) { return two.joined(oracle, t, 200); };
  double event = -1;  // the first t on a grid of 1/100 where the skin is joined
  for (int k = 1; k < 100 && event < 0; ++k)
    if (joined(k / 100.0)) event = k / 100.0;
  REQUIRE(event > 0.02);
  REQUIRE(event < 0.98);

  const std::vector<BallPair> live = live_pairs(source, target);
  const SkinComplex middle = build_skin_complex(interpolated_balls(source, target, live, 0.5), {0.5});
  const SkinComplex before = middle.with_balls(interpolated_balls(source, target, live, event - 0.01));
  const SkinComplex after = middle.with_balls(interpolated_balls(source, target, live, event));
  const SkinComplex early = middle.with_balls(interpolated_balls(source, target, live, 0.02));
  long across = 0, quiet = 0;
  for (int c = 0; c < static_cast<int>(middle.cells().size()); ++c) {
    const Eigen::Vector3d p = before.cell(c).center;  // any point: only the status is asked
    across += transport(before, after, c, p).status == TransportStatus::size_vanished;
    quiet += transport(early, before, c, p).status == TransportStatus::size_vanished;
  }
  // The neck opens in one step of 1/100 and in no earlier one.
  CHECK(across > 0);
  CHECK(quiet == 0);
}

namespace {

// The triangles of `mesh` failing the morph's frame criteria on `complex`
// (the mesher's public criteria and the outward check, as the morph judges).
long failing_triangles(const SkinComplex& complex, const SurfaceMesh& mesh, const MeshingOptions& criteria) {
  long failing = 0;
  for (const auto& t : mesh.triangles) {
    const std::array<Eigen::Vector3d, 3> corners{mesh.vertices[static_cast<size_t>(t[0])],
                                                 mesh.vertices[static_cast<size_t>(t[1])],
                                                 mesh.vertices[static_cast<size_t>(t[2])]};
    const auto r = restricted_triangle(complex, corners, criteria.tolerance, mesh.cells[static_cast<size_t>(t[0])]);
    failing += !r || triangle_defect(complex, *r, criteria) != TriangleDefect::none || !faces_outward(complex, *r);
  }
  return failing;
}

// A frame of 2k39 model 1 -> 3 at t = 0.3 moved to 0.31 as the morph moves
// it: transported in its cells, projected where it left them.
struct TransportedFrame {
  SurfaceMesh mesh;
  SkinComplex to;
  MorphOracle oracle;
};

TransportedFrame transported_2k39_frame() {
  const auto source = test::centred_model(test::data_file("2k39_3models.pdb"), 1);
  const auto target = test::centred_model(test::data_file("2k39_3models.pdb"), 3);
  const Morph morph = prepare_morph(source, target, 0.3);
  TransportedFrame f{morph.frame().mesh,
                     morph.complex().with_balls(interpolated_balls(source, target, morph.pairs(), 0.31)),
                     MorphOracle(source, target, 0.5)};
  for (size_t v = 0; v < f.mesh.vertices.size(); ++v) {
    const TransportedPoint moved = transport(morph.complex(), f.to, f.mesh.cells[v], f.mesh.vertices[v]);
    if (moved.status == TransportStatus::in_cell) {
      f.mesh.vertices[v] = moved.point;
    } else {
      const Projection p = f.to.project(moved.status == TransportStatus::left_cell ? moved.point : f.mesh.vertices[v],
                                        f.mesh.cells[v], 1e-14);
      REQUIRE(p.converged);
      f.mesh.vertices[v] = p.point;
      f.mesh.cells[v] = p.cell;
    }
    f.mesh.normals[v] = f.to.evaluate(f.mesh.vertices[v], f.mesh.cells[v]).gradient.normalized();
  }
  return f;
}

}  // namespace

// Transport is a similarity per cell; neighbouring cells scale differently
// and shear the triangles between them. Relaxation along the skin must undo
// much of that while every vertex stays exactly on the skin of B(t).
TEST_CASE("tangential relaxation keeps a transported frame on the skin and mends transport's shear", "[morph]") {
  TransportedFrame f = transported_2k39_frame();
  const MeshingOptions criteria = MorphOptions().frames;
  const long before = failing_triangles(f.to, f.mesh, criteria);
  const SurfaceMesh transported = f.mesh;
  relax_tangentially(f.to, f.mesh, RelaxationOptions{});
  const long after = failing_triangles(f.to, f.mesh, criteria);
  INFO("failing triangles: " << before << " transported, " << after << " relaxed");
  CHECK(before > 0);
  CHECK(2 * after <= before);
  double worst = 0, moved = 0;
  for (size_t v = 0; v < f.mesh.vertices.size(); ++v) {
    const MorphOracleResult o = f.oracle.evaluate(f.mesh.vertices[v], 0.31);
    REQUIRE(o.certified);
    worst = std::max(worst, o.distance());
    CHECK(f.to.membership_violation(f.mesh.cells[v], f.mesh.vertices[v]) <= 1e-9);
    moved = std::max(moved, (f.mesh.vertices[v] - transported.vertices[v]).norm());
  }
  CHECK(worst <= 1e-8);
  CHECK(moved > 1e-3);  // it did move vertices
  CHECK(f.mesh.triangles == transported.triangles);
}

// A vertex already near the centroid of its neighbours is settled: it
// stays, with no projection (RelaxationOptions::settled_below).
TEST_CASE("tangential relaxation leaves settled vertices where they are", "[morph]") {
  const TransportedFrame f = transported_2k39_frame();
  const size_t n = f.mesh.vertices.size();
  auto unmoved = [&](double settled_below) {
    SurfaceMesh mesh = f.mesh;
    RelaxationOptions options;
    options.settled_below = settled_below;
    relax_tangentially(f.to, mesh, options);
    size_t count = 0;
    for (size_t v = 0; v < n; ++v) count += mesh.vertices[v] == f.mesh.vertices[v];
    return count;
  };
  CHECK(unmoved(1e9) == n);  // every vertex settled
  const size_t settled = unmoved(RelaxationOptions{}.settled_below);
  INFO(settled << " of " << n << " vertices unmoved by default");
  CHECK(settled > 0);
  CHECK(settled < n / 2);
  CHECK(unmoved(0.0) < settled);
}

// Relaxing some vertices (`movable`) works on those alone: every vertex
// marked gives the whole relaxation's points, and one not marked stays
// where it was.
TEST_CASE("tangential relaxation of marked vertices moves those alone, as the whole relaxation moves them", "[morph]") {
  const TransportedFrame f = transported_2k39_frame();
  const size_t n = f.mesh.vertices.size();
  SurfaceMesh whole = f.mesh, all_marked = f.mesh, half = f.mesh;
  relax_tangentially(f.to, whole, RelaxationOptions{});
  const std::vector<char> every(n, 1);
  relax_tangentially(f.to, all_marked, RelaxationOptions{}, &every);
  CHECK(all_marked.vertices == whole.vertices);
  CHECK(all_marked.cells == whole.cells);
  std::vector<char> even(n, 0);
  for (size_t v = 0; v < n; v += 2) even[v] = 1;
  relax_tangentially(f.to, half, RelaxationOptions{}, &even);
  long moved = 0;
  for (size_t v = 0; v < n; ++v) {
    const bool unmoved = half.vertices[v] == f.mesh.vertices[v] && half.cells[v] == f.mesh.cells[v];
    if (!even[v]) CHECK(unmoved);
    moved += !unmoved;
  }
  CHECK(moved > 0);
}

TEST_CASE("tangential relaxation gives the same points with one thread as with several", "[morph]") {
  TransportedFrame f = transported_2k39_frame();
  SurfaceMesh one = f.mesh, many = f.mesh;
  tbb::task_arena(1).execute([&] { relax_tangentially(f.to, one, RelaxationOptions{}); });
  relax_tangentially(f.to, many, RelaxationOptions{});
  CHECK(one.vertices == many.vertices);
  CHECK(one.cells == many.cells);
}

// The moving-balls engine judges a step's triangles once, relaxes the
// corners of those that fail, and judges again only the triangles with a
// corner that moved. The verdicts must be those of judging every triangle.
TEST_CASE("judging again only triangles with a moved corner gives every triangle's verdict", "[morph]") {
  TransportedFrame f = transported_2k39_frame();
  const MeshingOptions criteria = MorphOptions().frames;
  std::vector<char> failing = detail::failing_triangles(f.to, f.mesh, f.mesh.triangles, criteria);
  std::vector<char> corners(f.mesh.vertices.size(), 0);
  for (size_t t = 0; t < failing.size(); ++t)
    if (failing[t])
      for (int v : f.mesh.triangles[t]) corners[static_cast<size_t>(v)] = 1;
  const SurfaceMesh before = f.mesh;
  relax_tangentially(f.to, f.mesh, RelaxationOptions{}, &corners);
  std::vector<char> moved(f.mesh.vertices.size(), 0);
  for (size_t v = 0; v < moved.size(); ++v)
    moved[v] = f.mesh.vertices[v] != before.vertices[v] || f.mesh.cells[v] != before.cells[v];
  const std::vector<char> judged_before = failing;
  detail::rejudge_moved(f.to, f.mesh, moved, criteria, failing);
  const std::vector<char> every = detail::failing_triangles(f.to, f.mesh, f.mesh.triangles, criteria);
  CHECK(failing == every);
  CHECK(failing != judged_before);  // the relaxation changed verdicts, so the test sees the re-judging
  long untouched = 0;
  for (const auto& t : f.mesh.triangles)
    untouched += !moved[static_cast<size_t>(t[0])] && !moved[static_cast<size_t>(t[1])] && !moved[static_cast<size_t>(t[2])];
  CHECK(untouched > static_cast<long>(f.mesh.triangles.size()) / 2);  // most were not judged again
  // Leaving out one moved corner's triangles loses a verdict that changed.
  std::vector<char> short_of_one = judged_before;
  for (size_t t = 0; t < every.size(); ++t)
    if (every[t] != judged_before[t]) {
      std::vector<char> fewer = moved;
      for (int v : f.mesh.triangles[t]) fewer[static_cast<size_t>(v)] = 0;
      detail::rejudge_moved(f.to, f.mesh, fewer, criteria, short_of_one);
      CHECK(short_of_one != every);
      break;
    }
}
