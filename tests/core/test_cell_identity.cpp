// The stable identity of a mixed cell: its ball tuple X. Checked against the
// oracle of docs/math.md section 2, whose minimiser's support is X for a point
// inside mu_X, and across two builds of the same balls in different orders.
#include "test_support.hpp"

#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_oracle.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <numeric>
#include <random>

using namespace skinmesh;

TEST_CASE("find_cell: every cell is found by its ball tuple, in any order", "[complex][identity]") {
  const auto balls = balls_from_molecule(read_molecule(test::data_file("pept.pdb")), 0.5);
  const SkinComplex complex = build_skin_complex(balls, {0.5});
  for (int c = 0; c < static_cast<int>(complex.cells().size()); ++c) {
    std::array<int, 4> key = complex.cell(c).balls;
    std::reverse(key.begin(), key.begin() + complex.cell(c).dim + 1);
    std::rotate(key.begin(), key.begin() + 1, key.end());  // the -1 padding first: any order is accepted
    REQUIRE(complex.find_cell(key) == c);
  }
  // Tuples that are no simplex: a ball with itself, and two balls far apart.
  CHECK(complex.find_cell({0, 0, -1, -1}) == -1);
  int far = 0;
  for (int b = 1; b < static_cast<int>(balls.size()); ++b)
    if ((balls[static_cast<size_t>(b)].center - balls[0].center).norm() >
        (balls[static_cast<size_t>(far)].center - balls[0].center).norm())
      far = b;
  CHECK(complex.find_cell({0, far, -1, -1}) == -1);
  // Every pair with ball 0: found exactly when some edge cell joins them.
  for (int b = 1; b < static_cast<int>(balls.size()); ++b) {
    const bool edge = std::any_of(complex.cells().begin(), complex.cells().end(), [&](const MixedCell& cell) {
      return cell.dim == 1 && cell.balls[0] == 0 && cell.balls[1] == b;
    });
    const int found = complex.find_cell({b, 0, -1, -1});
    REQUIRE((found >= 0) == edge);
    if (found >= 0) CHECK(complex.cell(found).balls == std::array<int, 4>{0, b, -1, -1});
  }
}

TEST_CASE("a point's cell survives rebuilding the complex from permuted balls", "[complex][identity]") {
  const auto balls = balls_from_molecule(read_molecule(test::data_file("3al1.pdb")), 0.5);
  // The same balls in another order: ball i of `balls` is ball where[i] of `shuffled`.
  std::vector<int> order(balls.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(11));
  std::vector<Ball> shuffled(balls.size());
  std::vector<int> where(balls.size());
  for (size_t k = 0; k < order.size(); ++k) {
    shuffled[k] = balls[static_cast<size_t>(order[k])];
    where[static_cast<size_t>(order[k])] = static_cast<int>(k);
  }
  const SkinComplex first = build_skin_complex(balls, {0.5});
  const SkinComplex second = build_skin_complex(shuffled, {0.5});
  const SkinOracle oracle(balls, 0.5);
  long checked = 0;
  for (const Eigen::Vector3d& x : test::sample_near_balls(balls, 0.5, 400, 0.8, 3)) {
    const OracleResult o = oracle.evaluate(x);
    REQUIRE(o.certified);
    // Away from cell boundaries only, where the support is exactly X.
    if (o.support.size() > 4 ||
        std::any_of(o.support.begin(), o.support.end(), [](const auto& p) { return p.second < 1e-6; }))
      continue;
    std::array<int, 4> x_first{{-1, -1, -1, -1}}, x_second{{-1, -1, -1, -1}};
    for (size_t k = 0; k < o.support.size(); ++k) {
      x_first[k] = o.support[k].first;
      x_second[k] = where[static_cast<size_t>(o.support[k].first)];
    }
    const int c1 = first.find_cell(x_first), c2 = second.find_cell(x_second);
    INFO("support of size " << o.support.size());
    REQUIRE(c1 >= 0);
    REQUIRE(c2 >= 0);
    CHECK(first.membership_violation(c1, x) <= 1e-9);
    CHECK(second.membership_violation(c2, x) <= 1e-9);
    CHECK(first.locate(x) == c1);
    // The same cell: the same centre and size.
    CHECK((first.cell(c1).center - second.cell(c2).center).norm() <= 1e-9);
    CHECK(first.cell(c1).R2 == Approx(second.cell(c2).R2).margin(1e-9));
    ++checked;
  }
  CHECK(checked > 300);
}

TEST_CASE("cells are numbered by dimension and ball tuple, whatever the heap holds", "[complex][identity]") {
  // CGAL reports an edge or facet from the cell with the smaller handle (a
  // memory address), so numbering in its order changed with the heap's
  // layout. Built once with the heap as it is and once after holding
  // allocations of assorted sizes, the two numberings must be the same: the
  // ascending order of (dimension, balls).
  const auto balls = balls_from_molecule(read_molecule(test::data_file("3al1.pdb")), 0.5);
  const SkinComplex first = build_skin_complex(balls, {0.5});
  std::vector<std::vector<char>> held;
  for (size_t k = 1; k < 400; ++k) held.emplace_back(k * 37 % 1000 + 8);
  const SkinComplex second = build_skin_complex(balls, {0.5});
  REQUIRE(first.cells().size() == second.cells().size());
  for (size_t c = 0; c < first.cells().size(); ++c) {
    REQUIRE(first.cells()[c].balls == second.cells()[c].balls);
    if (c > 0) {
      const MixedCell &a = first.cells()[c - 1], &b = first.cells()[c];
      REQUIRE((a.dim < b.dim || (a.dim == b.dim && a.balls < b.balls)));
    }
  }
  for (int i = 0; i < static_cast<int>(balls.size()); ++i) {
    const int v = first.vertex_cell(i);
    if (v >= 0) CHECK((first.cell(v).dim == 0 && first.cell(v).balls[0] == i));
  }
}
