// The interpolated ball set of a morph: the pair formula against docs/math.md's
// power identity, and the live pairs against the regular triangulation of
// all m*n pairs (CGAL, built here independently of the library's walk).
#include "test_support.hpp"

#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/error.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_oracle.hpp"

#include <catch2/catch.hpp>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <random>

using namespace skinmesh;

namespace {

// The pairs whose ball b_ij(1/2) is a vertex of the regular triangulation of
// all m*n balls.
std::vector<BallPair> non_hidden_of_all_pairs(const std::vector<Ball>& a, const std::vector<Ball>& b) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Vb = CGAL::Triangulation_vertex_base_with_info_3<long, K, CGAL::Regular_triangulation_vertex_base_3<K>>;
  using Tds = CGAL::Triangulation_data_structure_3<Vb, CGAL::Regular_triangulation_cell_base_3<K>>;
  using Regular = CGAL::Regular_triangulation_3<K, Tds>;
  std::vector<std::pair<K::Weighted_point_3, long>> points;
  const long n = static_cast<long>(b.size());
  for (size_t i = 0; i < a.size(); ++i)
    for (size_t j = 0; j < b.size(); ++j) {
      const Ball m = interpolate_ball(a[i], b[j], 0.5);
      points.emplace_back(K::Weighted_point_3(K::Point_3(m.center[0], m.center[1], m.center[2]), m.weight),
                          static_cast<long>(i) * n + static_cast<long>(j));
    }
  const Regular rt(points.begin(), points.end());
  std::vector<BallPair> out;
  for (auto v = rt.finite_vertices_begin(); v != rt.finite_vertices_end(); ++v)
    out.push_back({static_cast<int>(v->info() / n), static_cast<int>(v->info() % n)});
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST_CASE("an interpolated ball's power is the interpolated power", "[interpolation]") {
  // docs/math.md 1: pi_{(1-t) a + t b}(x) = (1-t) pi_a(x) + t pi_b(x) for every x.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-5, 5);
  for (int k = 0; k < 200; ++k) {
    const Ball a{Eigen::Vector3d(u(rng), u(rng), u(rng)), u(rng) + 5}, b{Eigen::Vector3d(u(rng), u(rng), u(rng)), u(rng) + 5};
    const double t = (u(rng) + 5) / 10;
    const Eigen::Vector3d x(u(rng), u(rng), u(rng));
    const Ball m = interpolate_ball(a, b, t);
    CHECK(m.power(x) == Approx((1 - t) * a.power(x) + t * b.power(x)).margin(1e-10));
  }
}

TEST_CASE("live pairs are the non-hidden balls of the full m*n set", "[interpolation]") {
  const auto pept = test::centred_model(test::data_file("pept.pdb"), 1);
  const auto al1 = test::centred_model(test::data_file("3al1.pdb"), 1);
  const auto live = live_pairs(pept, al1);
  CHECK(live == non_hidden_of_all_pairs(pept, al1));
  CHECK(live.size() < pept.size() * al1.size() / 10);  // about m + n, not m * n

  const auto m1 = test::centred_model(test::data_file("2k39_3models.pdb"), 1);
  const auto m2 = test::centred_model(test::data_file("2k39_3models.pdb"), 2);
  CHECK(live_pairs(m1, m2) == non_hidden_of_all_pairs(m1, m2));

  // Partial movement: most atoms stay, so the two power diagrams share
  // facets; pairs across a shared facet have an overlay cell of zero volume,
  // and whether such a ball counts as hidden is CGAL's symbolic perturbation's
  // choice, which depends on the points present. Such balls do not change the
  // skin: the oracle of docs/math.md 2 gives the same skin function for the live
  // set and for the full set's non-hidden balls, at t = 1/2.
  std::vector<Ball> moved = m1;
  for (size_t i = 0; i < moved.size(); i += 9) moved[i].center += Eigen::Vector3d(0.6, -0.3, 0.2);
  const auto partial = live_pairs(m1, moved);
  const auto reference = non_hidden_of_all_pairs(m1, moved);
  const SkinOracle walk(interpolated_balls(m1, moved, partial, 0.5), 0.5);
  const SkinOracle full(interpolated_balls(m1, moved, reference, 0.5), 0.5);
  std::mt19937 rng(5);
  std::uniform_int_distribution<size_t> pick(0, m1.size() - 1);
  std::uniform_real_distribution<double> u(-2.5, 2.5);
  for (int k = 0; k < 3000; ++k) {
    const Eigen::Vector3d x = m1[pick(rng)].center + Eigen::Vector3d(u(rng), u(rng), u(rng));
    const OracleResult a = walk.evaluate(x), b = full.evaluate(x);
    REQUIRE(a.certified);
    REQUIRE(b.certified);
    CHECK(std::abs(a.value - b.value) <= 1e-9 * std::max(1.0, std::abs(b.value)));
  }
  // An atom that does not move pairs with itself, and two that do not move
  // (i, j not multiples of 9) never pair with each other.
  CHECK(std::binary_search(partial.begin(), partial.end(), BallPair{1, 1}));
  for (const BallPair& p : partial)
    if (p.source % 9 != 0 && p.target % 9 != 0) CHECK(p.source == p.target);
  // A set onto itself: each of its non-hidden balls with itself, nothing else.
  std::vector<BallPair> own;
  for (const BallPair& p : non_hidden_of_all_pairs(m1, m1))
    if (p.source == p.target) own.push_back(p);
  CHECK(live_pairs(m1, m1) == own);
}

TEST_CASE("with_balls with known cells: those take the given centre and size and keep their directions",
          "[interpolation]") {
  const auto m1 = test::centred_model(test::data_file("2k39_3models.pdb"), 1);
  const auto m2 = test::centred_model(test::data_file("2k39_3models.pdb"), 2);
  const auto live = live_pairs(m1, m2);
  const SkinComplex middle = build_skin_complex(interpolated_balls(m1, m2, live, 0.5), {0.5});
  int edge = 0;
  while (middle.cell(edge).dim != 1) ++edge;
  const Eigen::Vector3d centre(1.5, -2.0, 0.25);
  const SkinComplex moved = middle.with_balls(interpolated_balls(m1, m2, live, 0.3), {{edge, centre, 0.75}});
  const SkinComplex plain = middle.with_balls(interpolated_balls(m1, m2, live, 0.3));
  CHECK(moved.cell(edge).center == centre);
  CHECK(moved.cell(edge).R2 == 0.75);
  CHECK(moved.cell(edge).P == middle.cell(edge).P);
  // Every other cell as with_balls alone makes it.
  const int other = edge + 1;
  CHECK(moved.cell(other).center == plain.cell(other).center);
  CHECK(moved.cell(other).R2 == plain.cell(other).R2);
  CHECK_THROWS_AS(middle.with_balls(interpolated_balls(m1, m2, live, 0.3), {{-1, centre, 0.0}}), ContractError);
  const int past = static_cast<int>(middle.cells().size());
  CHECK_THROWS_AS(middle.with_balls(interpolated_balls(m1, m2, live, 0.3), {{past, centre, 0.0}}), ContractError);
  // Listed out of order (or twice), a cell could be written by two threads.
  CHECK_THROWS_AS(middle.with_balls(interpolated_balls(m1, m2, live, 0.3), {{other, centre, 0.0}, {edge, centre, 0.0}}),
                  ContractError);
  CHECK_THROWS_AS(middle.with_balls(interpolated_balls(m1, m2, live, 0.3), {{edge, centre, 0.0}, {edge, centre, 0.0}}),
                  ContractError);
}

TEST_CASE("with_balls into a complex moved before: every cell and ball as a fresh move makes them", "[interpolation]") {
  const auto m1 = test::centred_model(test::data_file("2k39_3models.pdb"), 1);
  const auto m2 = test::centred_model(test::data_file("2k39_3models.pdb"), 2);
  const auto live = live_pairs(m1, m2);
  const SkinComplex middle = build_skin_complex(interpolated_balls(m1, m2, live, 0.5), {0.5});
  int edge = 0;
  while (middle.cell(edge).dim != 1) ++edge;
  const std::vector<SkinComplex::KnownCell> known{{edge, Eigen::Vector3d(0.5, 1.0, -1.0), 0.25}};
  // The storage of another complex (the source's own, other cells) and of a
  // frame moved before (at t = 0.7 only the geometry is written, the
  // combinatorics being the same): neither may leave anything behind.
  SkinComplex reused = build_skin_complex(m1, {0.5});
  for (double t : {0.2, 0.7}) {
    middle.with_balls(interpolated_balls(m1, m2, live, t), known, reused);
    const SkinComplex fresh = middle.with_balls(interpolated_balls(m1, m2, live, t), known);
    REQUIRE(reused.cells().size() == fresh.cells().size());
    REQUIRE(reused.balls().size() == fresh.balls().size());
    for (size_t b = 0; b < fresh.balls().size(); ++b) {
      CHECK(reused.balls()[b].center == fresh.balls()[b].center);
      CHECK(reused.balls()[b].weight == fresh.balls()[b].weight);
    }
    for (size_t c = 0; c < fresh.cells().size(); ++c) {
      const MixedCell &a = reused.cells()[c], &b = fresh.cells()[c];
      CHECK((a.balls == b.balls && a.center == b.center && a.R2 == b.R2 && a.P == b.P && a.to_affine == b.to_affine &&
             a.degenerate == b.degenerate));
    }
    // And it answers queries as the fresh one does (faces, cofaces, grid).
    const Eigen::Vector3d x = fresh.cell(edge).center + Eigen::Vector3d(0.3, -0.2, 0.1);
    CHECK(reused.locate(x) == fresh.locate(x));
  }
  SkinComplex self = middle;
  CHECK_THROWS_AS(self.with_balls(interpolated_balls(m1, m2, live, 0.3), known, self), ContractError);
}

TEST_CASE("a side holding the same ball twice: B(t) is that of its distinct balls", "[interpolation][bad]") {
  // A duplicated atom is the same ball twice; the union, and so the skin,
  // is that of the distinct balls. The live pairs of pept -> pept with one
  // atom twice give the skin function of pept -> pept, by the oracle of
  // docs/math.md section 2, and of the full m*n set's non-hidden balls.
  const auto pept = test::centred_model(test::data_file("pept.pdb"), 1);
  std::vector<Ball> twice = pept;
  twice.push_back(pept[10]);
  for (const double t : {0.25, 0.5}) {
    const SkinOracle dup(interpolated_balls(pept, twice, live_pairs(pept, twice), t), 0.5);
    const SkinOracle plain(interpolated_balls(pept, pept, live_pairs(pept, pept), t), 0.5);
    std::mt19937 rng(7);
    std::uniform_int_distribution<size_t> pick(0, pept.size() - 1);
    std::uniform_real_distribution<double> u(-2.5, 2.5);
    for (int k = 0; k < 2000; ++k) {
      const Eigen::Vector3d x = pept[pick(rng)].center + Eigen::Vector3d(u(rng), u(rng), u(rng));
      const OracleResult a = dup.evaluate(x), b = plain.evaluate(x);
      REQUIRE(a.certified);
      REQUIRE(b.certified);
      CHECK(std::abs(a.value - b.value) <= 1e-9 * std::max(1.0, std::abs(b.value)));
    }
  }
  // One ball onto the same ball twice (and back): B(t) is that ball.
  const std::vector<Ball> one{{Eigen::Vector3d(1, 2, 3), 4.0}}, two{one[0], one[0]};
  for (const auto& [from, to] : {std::pair{one, two}, std::pair{two, one}}) {
    const std::vector<Ball> b = interpolated_balls(from, to, live_pairs(from, to), 0.5);
    REQUIRE(b.size() == 1);
    CHECK(b[0].center == one[0].center);
    CHECK(b[0].weight == one[0].weight);
  }
}

TEST_CASE("balls moved less than kUnmovedWithin are put on their source ball and the others stay", "[interpolation]") {
  const std::vector<Ball> source{{Eigen::Vector3d(0, 0, 0), 4.0}, {Eigen::Vector3d(3, 0, 0), 4.0},
                                 {Eigen::Vector3d(3, 0, 2e-4), 4.0}, {Eigen::Vector3d(0, 5, 0), 2.0}};
  std::vector<Ball> target{{Eigen::Vector3d(1e-9, -2e-9, 0), 4.0},  // onto source 0
                           {Eigen::Vector3d(3, 0, 1.5e-4), 4.0},    // nearer source 2 than source 1
                           {Eigen::Vector3d(0, 5 + 3e-4, 0), 4.0},  // near source 3, another weight: stays
                           {Eigen::Vector3d(0, 0, 6e-4), 4.0}};     // beyond kUnmovedWithin: stays
  const std::vector<Ball> given = target;
  CHECK(snap_unmoved_balls(source, target) == 2);
  CHECK(target[0].center == source[0].center);
  CHECK(target[1].center == source[2].center);
  CHECK(target[2].center == given[2].center);
  CHECK(target[3].center == given[3].center);
  for (size_t k = 0; k < target.size(); ++k) CHECK(target[k].weight == given[k].weight);
  // The pairs of two snapped balls drop out of the live pairs: with every
  // target ball on its source ball, only the pairs (i, i) are left.
  std::vector<Ball> copy = source;
  for (Ball& b : copy) b.center += Eigen::Vector3d(1e-6, -1e-6, 1e-6);
  CHECK(snap_unmoved_balls(source, copy) == static_cast<long>(source.size()));
  CHECK(live_pairs(source, copy).size() == source.size());
}
