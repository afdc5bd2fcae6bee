// The mixed-cell quadrics against the independent oracle of docs/math.md section 2.
#include "test_support.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_oracle.hpp"

#include <catch2/catch.hpp>

#include <CGAL/Exact_rational.h>

#include <algorithm>
#include <array>
#include <cmath>

using namespace skinmesh;

namespace {

struct Agreement {
  long points = 0;
  long sign_mismatches = 0;
  long uncertified = 0;
  double worst_relative = 0;
};

// Q_X(x) from the located cell against (1-s) F_B(x) from the oracle.
Agreement compare_with_oracle(const std::vector<Ball>& balls, double s, const std::vector<Eigen::Vector3d>& points) {
  const SkinComplex sc = build_skin_complex(balls, {s});
  const SkinOracle oracle(balls, s);
  Agreement a;
  int hint = -1;
  for (const Eigen::Vector3d& x : points) {
    const int cell = sc.locate(x, hint);
    hint = cell;
    const double q = sc.quadric(cell, x);
    const OracleResult o = oracle.evaluate(x);
    if (!o.certified) ++a.uncertified;
    const double expected = (1 - s) * o.value;
    // Relative to the value, with 1 A^2 as the unit below which it is absolute.
    const double relative = std::abs(q - expected) / std::max(1.0, std::abs(expected));
    a.worst_relative = std::max(a.worst_relative, relative);
    if ((q > 0) != (expected > 0) && std::abs(expected) > 1e-12) ++a.sign_mismatches;
    ++a.points;
  }
  return a;
}

void check_molecule(const std::string& path, double s, WeightConvention convention, unsigned seed) {
  const Molecule m = read_molecule(path);
  const auto balls = balls_from_molecule(m, s, convention);
  const auto points = test::sample_near_balls(balls, s, 10000, 1.5, seed);
  const Agreement a = compare_with_oracle(balls, s, points);
  INFO(path << ": " << a.points << " points, worst relative difference " << a.worst_relative);
  CHECK(a.points >= 10000);
  CHECK(a.uncertified == 0);
  CHECK(a.sign_mismatches == 0);
  CHECK(a.worst_relative <= 1e-9);
}

}  // namespace

TEST_CASE("quadric equals (1-s) times the oracle on pept", "[skin][oracle]") {
  check_molecule(test::data_file("pept.pdb"), 0.5, WeightConvention::GrowBySkin, 1);
}

TEST_CASE("quadric equals (1-s) times the oracle on 3al1", "[skin][oracle]") {
  check_molecule(test::data_file("3al1.pdb"), 0.5, WeightConvention::GrowBySkin, 2);
}

TEST_CASE("quadric equals (1-s) times the oracle on 1ubi", "[skin][oracle]") {
  check_molecule(test::data_file("1ubi.pdb"), 0.5, WeightConvention::GrowBySkin, 3);
}

TEST_CASE("quadric equals the oracle for other shrink factors and raw weights", "[skin][oracle]") {
  for (double s : {0.2, 0.35, 0.8}) {
    const Molecule m = read_molecule(test::data_file("pept.pdb"));
    const auto balls = balls_from_molecule(m, s, WeightConvention::Raw);
    const Agreement a = compare_with_oracle(balls, s, test::sample_near_balls(balls, s, 2000, 1.0, 7));
    INFO("s = " << s << ", worst relative " << a.worst_relative);
    CHECK(a.sign_mismatches == 0);
    CHECK(a.uncertified == 0);
    CHECK(a.worst_relative <= 1e-9);
  }
}

TEST_CASE("low-dimensional ball sets give the true skin", "[skin][oracle][degenerate]") {
  const double s = 0.5;
  std::vector<std::pair<std::string, std::vector<Ball>>> sets = {
      {"one ball", {{{1, 2, 3}, 4.0}}},
      {"two overlapping balls", {{{0, 0, 0}, 4.0}, {{2.5, 0, 0}, 3.0}}},
      {"two separate balls", {{{0, 0, 0}, 1.0}, {{9, 0, 0}, 1.0}}},
      {"balls on a line", {{{0, 0, 0}, 3.0}, {{1.5, 0, 0}, 3.0}, {{3.0, 0, 0}, 2.0}, {{5.2, 0, 0}, 3.5}}},
      {"balls on a plane",
       {{{0, 0, 0}, 3.0}, {{2, 0, 0}, 3.0}, {{0, 2.2, 0}, 2.5}, {{2.1, 2.0, 0}, 3.0}, {{1, 4, 0}, 2.0}}},
      {"a ball swallowed by another", {{{0, 0, 0}, 9.0}, {{0.5, 0, 0}, 1.0}, {{4, 0, 0}, 4.0}}},
  };
  for (const auto& [name, balls] : sets) {
    const SkinComplex sc = build_skin_complex(balls, {s});
    const Agreement a = compare_with_oracle(balls, s, test::sample_near_balls(balls, s, 3000, 2.0, 11));
    INFO(name << ": dimension " << sc.triangulation_dimension() << ", worst relative " << a.worst_relative);
    CHECK(a.sign_mismatches == 0);
    CHECK(a.uncertified == 0);
    CHECK(a.worst_relative <= 1e-9);
  }
}

TEST_CASE("a swallowed ball is reported hidden", "[skin][hidden]") {
  const SkinComplex sc = build_skin_complex({{{0, 0, 0}, 9.0}, {{0.5, 0, 0}, 1.0}, {{4, 0, 0}, 4.0}}, {0.5});
  REQUIRE(sc.hidden_balls().size() == 1);
  CHECK(sc.hidden_balls()[0] == 1);
  CHECK(sc.vertex_cell(1) == -1);
}

TEST_CASE("one ball: the skin is the sphere of radius sqrt(s w)", "[skin]") {
  const double s = 0.5, w = 4.0;
  const SkinComplex sc = build_skin_complex({{{1, 2, 3}, w}}, {s});
  CHECK(sc.triangulation_dimension() == 0);
  const Eigen::Vector3d on(1 + std::sqrt(s * w), 2, 3);
  CHECK(std::abs(sc.value(on)) < 1e-12);
  CHECK(sc.value(Eigen::Vector3d(1, 2, 3)) < 0);
  CHECK(sc.value(Eigen::Vector3d(5, 2, 3)) > 0);
}

// The oracle checks near balls one by one and far ones by a bound
// (docs/math.md section 2), found in a grid of centres. With one ball the skin
// function is |x - z|^2 - s w exactly; points far outside the grid, and a
// point that is not finite, must neither hang nor be certified wrongly (a far
// point once overflowed the grid's integer cell index and looped for ever).
TEST_CASE("the oracle: one ball exactly, far points, a point that is not finite", "[skin][oracle]") {
  const double s = 0.5, w = 4.0;
  const Eigen::Vector3d z(1, 2, 3);
  const SkinOracle one({{z, w}}, s);
  for (const Eigen::Vector3d& x : {Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(2.4, 2, 3), Eigen::Vector3d(1e6, -3e7, 2),
                                   Eigen::Vector3d(-1e300, 0, 0)}) {
    INFO(x.transpose());
    const OracleResult o = one.evaluate(x);
    CHECK(o.certified);
    CHECK(o.value == Approx((x - z).squaredNorm() - s * w).epsilon(1e-12));
  }
  const OracleResult not_finite = one.evaluate(Eigen::Vector3d(NAN, 0, 0));
  CHECK_FALSE(not_finite.certified);
  CHECK(not_finite.distance() == INFINITY);
  // Many balls: far points are outside every ball's reach, and the value is
  // the least power distance's skin value there, certified.
  const auto balls = balls_from_molecule(read_molecule(test::data_file("pept.pdb")), s);
  const SkinOracle oracle(balls, s);
  for (const Eigen::Vector3d& x : {Eigen::Vector3d(1e4, 0, 0), Eigen::Vector3d(0, -1e8, 3e7)}) {
    const OracleResult o = oracle.evaluate(x);
    CHECK(o.certified);
    CHECK(o.value > 0);
  }
}

// Regression: at skin points next to four nearly coplanar centres ~100 A from
// the origin, the oracle's KKT system used to be judged singular from the
// absolute Gram matrix, and its active-set loop stalled uncertified (3mht,
// 0.13 A apparent error). On-skin points of a large molecule, and the same
// points after moving everything 1000 A away, must all be certified zeros.
TEST_CASE("the oracle is certified on the skin and far from the origin", "[skin][oracle]") {
  const double s = 0.5;
  const auto balls = balls_from_molecule(read_molecule(test::data_file("3mht.pdb")), s, WeightConvention::GrowBySkin);
  const SkinComplex sc = build_skin_complex(balls, {s});
  const auto near = test::sample_near_balls(balls, s, 4000, 1.0, 21);
  const Eigen::Vector3d shift(1000.0, -2000.0, 500.0);
  std::vector<Ball> moved = balls;
  for (Ball& b : moved) b.center += shift;
  const SkinOracle oracle(balls, s), moved_oracle(moved, s);
  long uncertified = 0, projected = 0;
  double worst = 0, worst_moved = 0;
  for (const Eigen::Vector3d& x : near) {
    const Projection p = sc.project(x);
    if (!p.converged) continue;
    ++projected;
    const OracleResult o = oracle.evaluate(p.point), m = moved_oracle.evaluate(p.point + shift);
    uncertified += !o.certified + !m.certified;
    worst = std::max(worst, o.distance());
    worst_moved = std::max(worst_moved, m.distance());
  }
  INFO(projected << " skin points; worst distance " << worst << " A, after the shift " << worst_moved << " A");
  CHECK(projected == static_cast<long>(near.size()));  // buried points too: the ray fallback of project()
  CHECK(uncertified == 0);
  CHECK(worst <= 1e-9);
  CHECK(worst_moved <= 1e-6);  // 1000 A coordinates keep ~12 digits of the local geometry
}

TEST_CASE("the oracle started from given balls gives the answer it gives from the balls of least power",
          "[skin][oracle]") {
  // The start only changes where the solve begins: from the balls of each
  // point's mixed cell, from balls far from it, from one ball, the answer is
  // the same minimiser, certified against every ball.
  const double s = 0.5;
  const auto balls = balls_from_molecule(read_molecule(test::data_file("1ubi.pdb")), s);
  const SkinComplex sc = build_skin_complex(balls, {s});
  const SkinOracle oracle(balls, s);
  const auto near = test::sample_near_balls(balls, s, 2000, 1.0, 7);
  const int far_ball = 0;
  long compared = 0;
  for (const Eigen::Vector3d& x : near) {
    const Projection p = sc.project(x);
    std::vector<Eigen::Vector3d> points{x};  // near the skin, and on it
    if (p.converged) points.push_back(p.point);
    for (const Eigen::Vector3d& point : points) {
      const int cell = sc.locate(point);
      const OracleResult plain = oracle.evaluate(point);
      REQUIRE(plain.certified);
      for (const std::array<int, 4>& start : {sc.cell(cell).balls, std::array<int, 4>{far_ball, -1, -1, -1},
                                               std::array<int, 4>{-1, -1, -1, -1}}) {
        const OracleResult o = oracle.evaluate(point, start);
        INFO("start " << start[0] << " " << start[1] << " " << start[2] << " " << start[3]);
        CHECK(o.certified);
        CHECK(std::abs(o.value - plain.value) <= 1e-12 * (1 + std::abs(plain.value)));
        CHECK((o.gradient - plain.gradient).norm() <= 1e-10 * (1 + plain.gradient.norm()));
        ++compared;
      }
    }
  }
  CHECK(compared >= 3 * 2 * 1900);
  CHECK_THROWS_AS(oracle.evaluate(near[0], {static_cast<int>(balls.size()), -1, -1, -1}), ContractError);
}

TEST_CASE("the gradient read in a crossing's own cell is the oracle's", "[skin][oracle][segment]") {
  // faces_outward reads the gradient at a triangle's surface ball centre,
  // a crossing of its normal line, in the cell the walk found it in,
  // without locating the point again: on the cell's boundary too (the skin
  // is C1), it must be the skin's gradient there.
  const double s = 0.5;
  const auto balls = balls_from_molecule(read_molecule(test::data_file("1ubi.pdb")), s);
  const SkinComplex sc = build_skin_complex(balls, {s});
  const SkinOracle oracle(balls, s);
  const auto near = test::sample_near_balls(balls, s, 400, 1.0, 11);
  long crossings = 0;
  for (size_t i = 0; i + 1 < near.size(); i += 2)
    for (const SegmentCrossing& c : sc.intersect_segment(near[i], near[i + 1])) {
      const OracleResult o = oracle.evaluate(c.point);
      REQUIRE(o.certified);
      const Eigen::Vector3d g = sc.gradient(c.cell, c.point);
      CHECK((g - o.gradient).norm() <= 1e-9 * (1 + o.gradient.norm()));
      CHECK((g.dot(near[i + 1] - near[i]) < 0) == c.entering);
      ++crossings;
    }
  CHECK(crossings >= 200);
}

TEST_CASE("cospherical and interpolated ball sets: skin function and crossings equal the oracle",
          "[skin][oracle][degenerate][segment]") {
  const double s = 0.5;
  auto sets = test::symmetric_ball_sets();
  // The exact B(1/2) of two morphs (docs/math.md 4): groups of balls orthogonal to
  // one sphere everywhere, which CGAL splits into flat tetrahedra.
  sets.push_back({"B(1/2) pept -> 3al1", test::midway(test::centred_model(test::data_file("pept.pdb"), 1),
                                                      test::centred_model(test::data_file("3al1.pdb"), 1))});
  sets.push_back({"B(1/2) 2k39 model 1 -> 2",
                  test::midway(test::centred_model(test::data_file("2k39_3models.pdb"), 1),
                               test::centred_model(test::data_file("2k39_3models.pdb"), 2))});
  for (const auto& [name, balls] : sets) {
    INFO(name);
    const SkinComplex sc = build_skin_complex(balls, {s});
    if (name.rfind("B(1/2)", 0) == 0) CHECK(sc.degenerate_cell_count() > 0);  // flat cells are exercised
    const auto points = test::sample_near_balls(balls, s, 4000, 2.0, 17);
    const Agreement a = compare_with_oracle(balls, s, points);
    INFO("worst relative " << a.worst_relative);
    CHECK(a.uncertified == 0);
    CHECK(a.sign_mismatches == 0);
    CHECK(a.worst_relative <= 1e-9);
    // Every crossing of a segment is on the skin by the oracle, and the sign
    // of F changes between consecutive crossings as they say.
    const SkinOracle oracle(balls, s);
    long crossings = 0, off = 0, wrong_sign = 0;
    for (size_t k = 0; k + 1 < points.size(); k += 2) {
      const Eigen::Vector3d p = points[k], q = points[k] + 2.0 * (points[k + 1] - points[k]).normalized();
      const auto found = sc.intersect_segment(p, q);
      for (const SegmentCrossing& c : found) {
        ++crossings;
        if (oracle.evaluate(c.point).distance() > 1e-9) ++off;
      }
      // Between crossings (and before the first) F keeps one sign.
      double t0 = 0;
      for (size_t i = 0; i <= found.size(); ++i) {
        const double t1 = i < found.size() ? found[i].t : 1.0;
        if (t1 - t0 > 1e-6) {
          const double mid = oracle.evaluate(p + 0.5 * (t0 + t1) * (q - p)).value;
          const bool inside_expected = i < found.size() ? found[i].entering == false : (found.empty()
                                                                                          ? oracle.evaluate(p).value < 0
                                                                                          : found.back().entering);
          if (std::abs(mid) > 1e-9 && (mid < 0) != inside_expected) {
            ++wrong_sign;
            WARN("sign: F " << mid << " on (" << t0 << ", " << t1 << ") of " << p.transpose() << " -> "
                                     << q.transpose() << ", " << found.size() << " crossings");
          }
        }
        t0 = t1;
      }
    }
    INFO(crossings << " crossings");
    CHECK(crossings > 100);
    CHECK(off == 0);
    CHECK(wrong_sign == 0);
  }
}

namespace {

// The centre z in aff(X) with equal power R2 to every ball of X, in exact
// rational arithmetic: z = z_0 + E a with (E^T E) a = rhs / 2 (docs/math.md
// section 3), E's columns the edges from the first ball, solved by Gaussian
// elimination (exact, so the normal equations lose nothing).
struct ExactOrthosphere {
  Eigen::Vector3d center;
  double R2;
};

ExactOrthosphere exact_orthosphere(const std::vector<Ball>& b) {
  using Q = CGAL::Exact_rational;
  const size_t d = b.size() - 1;
  std::vector<std::array<Q, 3>> E(d);
  std::vector<std::vector<Q>> M(d, std::vector<Q>(d + 1));  // [E^T E | rhs / 2]
  for (size_t j = 0; j < d; ++j)
    for (int k = 0; k < 3; ++k) E[j][k] = Q(b[j + 1].center[k]) - Q(b[0].center[k]);
  for (size_t i = 0; i < d; ++i) {
    Q length2 = 0;
    for (int k = 0; k < 3; ++k) length2 += E[i][k] * E[i][k];
    M[i][d] = (length2 - Q(b[i + 1].weight) + Q(b[0].weight)) / 2;
    for (size_t j = 0; j < d; ++j)
      for (int k = 0; k < 3; ++k) M[i][j] += E[i][k] * E[j][k];
  }
  for (size_t c = 0; c < d; ++c) {  // elimination; the Gram matrix is positive definite
    for (size_t r = 0; r < d; ++r) {
      if (r == c) continue;
      const Q f = M[r][c] / M[c][c];
      for (size_t k = c; k <= d; ++k) M[r][k] -= f * M[c][k];
    }
  }
  std::array<Q, 3> offset{0, 0, 0};
  for (size_t j = 0; j < d; ++j)
    for (int k = 0; k < 3; ++k) offset[k] += M[j][d] / M[j][j] * E[j][k];
  Q R2 = -Q(b[0].weight);
  for (int k = 0; k < 3; ++k) R2 += offset[k] * offset[k];
  Eigen::Vector3d center;
  for (int k = 0; k < 3; ++k) center[k] = CGAL::to_double(Q(b[0].center[k]) + offset[k]);
  return {center, CGAL::to_double(R2)};
}

}  // namespace

// Nearly flat tetrahedra and triangles (not flat enough to count as
// degenerate) away from the origin, as a protein's nearly flat Delaunay
// simplices are: a fourth vertex close to the plane of a triangle (the centre
// far away), a sliver (four vertices near one circle, the centre near them)
// and a triangle with one vertex near the line of the other two. Their
// orthosphere solved through the normal equations (E^T E) lost the square of
// E's condition: on 1ubi -> 1hpv such a cell's size was 1e-8 A^2 off and a
// morph frame's vertex 2.6e-8 A off the skin (core/src/build_skin_complex.cpp).
TEST_CASE("a nearly flat simplex's centre and size match exact arithmetic", "[skin][degenerate]") {
  const Eigen::Vector3d at(31.7, -18.3, 12.9);
  const auto on_circle = [&](double degrees, double z) {
    const double a = degrees * M_PI / 180;
    return Eigen::Vector3d(at + 1.6 * Eigen::Vector3d(std::cos(a), std::sin(a), 0) + Eigen::Vector3d(0, 0, z));
  };
  for (const double height : {1e-2, 3e-3, 1e-3}) {
    const std::vector<std::vector<Ball>> shapes{{{at, 2.1},
                                                 {at + Eigen::Vector3d(3.1, 0.2, 0), 2.4},
                                                 {at + Eigen::Vector3d(0.3, 2.9, 0), 1.9},
                                                 {at + Eigen::Vector3d(1.2, 1.1, height), 2.2}},
                                                {{on_circle(0, height), 1.2},
                                                 {on_circle(95, -height), 1.25},
                                                 {on_circle(185, height), 1.2},
                                                 {on_circle(272, -height), 1.15}},
                                                {{at, 1.1},
                                                 {at + Eigen::Vector3d(1.4, 0.3, -0.2), 1.2},
                                                 {at + Eigen::Vector3d(2.9, 0.6 + height, -0.4), 1.0}}};
    for (const std::vector<Ball>& balls : shapes) {
      const int dim = static_cast<int>(balls.size()) - 1;
      const SkinComplex sc = build_skin_complex(balls, {0.5});
      const auto cell = std::find_if(sc.cells().begin(), sc.cells().end(), [&](const MixedCell& c) { return c.dim == dim; });
      REQUIRE(cell != sc.cells().end());
      CHECK_FALSE(cell->degenerate);
      std::vector<Ball> own;
      for (int k = 0; k <= dim; ++k) own.push_back(sc.balls()[static_cast<size_t>(cell->balls[static_cast<size_t>(k)])]);
      const ExactOrthosphere exact = exact_orthosphere(own);
      INFO("dimension " << dim << ", height " << height << ": R2 " << cell->R2 << " exactly " << exact.R2);
      // Rounding the inputs' differences costs about 1e-16 times E's
      // condition (up to ~1e4 here) relative to the centre's distance.
      const double scale = std::max(1.0, (exact.center - own[0].center).norm());
      CHECK(std::abs(cell->R2 - exact.R2) <= 1e-12 * scale * scale);
      CHECK((cell->center - exact.center).norm() <= 1e-12 * scale);
    }
  }
}
