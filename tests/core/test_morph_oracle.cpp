// The morph oracle (docs/math.md section 4): F_t over m + n unknowns, checked
// against the skin oracle of all m*n interpolated balls (no complex, no live
// pairs in either) and then used as the reference for the mixed complex of
// the live pairs of B(t), as every frame of a morph will be.
#include "test_support.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_oracle.hpp"

#include <catch2/catch.hpp>

#include <random>

using namespace skinmesh;

namespace {

// Points around the balls of both molecules, up to `spread` A off their
// centres, and around the midpoints the interpolated balls pass through.
std::vector<Eigen::Vector3d> points_between(const std::vector<Ball>& a, const std::vector<Ball>& b, double t,
                                            int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<size_t> pick_a(0, a.size() - 1), pick_b(0, b.size() - 1);
  std::uniform_real_distribution<double> u(-2.5, 2.5);
  std::vector<Eigen::Vector3d> points;
  for (int k = 0; k < count; ++k) {
    const Eigen::Vector3d c = (1 - t) * a[pick_a(rng)].center + t * b[pick_b(rng)].center;
    points.push_back(c + Eigen::Vector3d(u(rng), u(rng), u(rng)));
  }
  return points;
}

}  // namespace

TEST_CASE("morph oracle: F_t equals the skin oracle of all m*n interpolated balls", "[oracle][morph]") {
  const auto pept = test::centred_model(test::data_file("pept.pdb"), 1);
  const auto al1 = test::centred_model(test::data_file("3al1.pdb"), 1);
  const MorphOracle morph(pept, al1, 0.5);
  for (double t : {0.2, 0.5, 0.85}) {
    INFO("t = " << t);
    const SkinOracle all(interpolated_balls(pept, al1, all_pairs(pept.size(), al1.size()), t), 0.5);
    for (const Eigen::Vector3d& x : points_between(pept, al1, t, 150, 3)) {
      const MorphOracleResult m = morph.evaluate(x, t);
      const OracleResult o = all.evaluate(x);
      REQUIRE(m.certified);
      REQUIRE(o.certified);
      CHECK(std::abs(m.value - o.value) <= 1e-9 * std::max(1.0, std::abs(o.value)));
      CHECK((m.gradient - o.gradient).norm() <= 1e-7 * std::max(1.0, o.gradient.norm()));
      double weight = 0;
      for (const auto& [pair, w] : m.support) weight += w;
      CHECK(weight == Approx(1.0).margin(1e-12));
    }
  }
}

TEST_CASE("morph oracle: the ends are the source's and the target's skins", "[oracle][morph]") {
  const auto m1 = test::centred_model(test::data_file("2k39_3models.pdb"), 1);
  const auto m2 = test::centred_model(test::data_file("2k39_3models.pdb"), 2);
  const MorphOracle morph(m1, m2, 0.5);
  const SkinOracle source(m1, 0.5), target(m2, 0.5);
  for (const Eigen::Vector3d& x : points_between(m1, m2, 0.5, 200, 9)) {
    CHECK(morph.evaluate(x, 0.0).value == source.evaluate(x).value);
    CHECK(morph.evaluate(x, 1.0).value == target.evaluate(x).value);
    // Just inside the ends, F_t is continuous in t.
    CHECK(std::abs(morph.evaluate(x, 1e-9).value - source.evaluate(x).value) <= 1e-5);
  }
  CHECK_THROWS_AS(morph.evaluate(Eigen::Vector3d::Zero(), 1.5), ContractError);
}

TEST_CASE("morph oracle: the complex of the live pairs of B(t) has the frame's skin function", "[oracle][morph]") {
  const auto m1 = test::centred_model(test::data_file("2k39_3models.pdb"), 1);
  const auto m2 = test::centred_model(test::data_file("2k39_3models.pdb"), 2);
  const MorphOracle morph(m1, m2, 0.5);
  const std::vector<BallPair> live = live_pairs(m1, m2);
  for (double t : {0.1, 0.5, 0.9}) {
    INFO("t = " << t);
    const SkinComplex complex = build_skin_complex(interpolated_balls(m1, m2, live, t), {0.5});
    int hint = -1;
    for (const Eigen::Vector3d& x : points_between(m1, m2, t, 1000, 17)) {
      const MorphOracleResult m = morph.evaluate(x, t);
      REQUIRE(m.certified);
      const SkinEval e = complex.evaluate(x, hint);
      hint = e.cell;
      CHECK(std::abs(e.value - m.value) <= 1e-9 * std::max(1.0, std::abs(m.value)));
      CHECK((e.value < 0) == (m.value < 0));
    }
  }
}

TEST_CASE("morph oracle: started from the pairs of a point's overlay cell, it gives the answer it gives alone",
          "[oracle][morph]") {
  // The start only changes where the pair solve begins: from the live pairs
  // of the cell of B(t)'s complex holding the point, from one far pair, from
  // none, the answer is the same, certified against all m x n pairs.
  const auto m1 = test::centred_model(test::data_file("2k39_3models.pdb"), 1);
  const auto m3 = test::centred_model(test::data_file("2k39_3models.pdb"), 3);
  const MorphOracle morph(m1, m3, 0.5);
  const std::vector<BallPair> live = live_pairs(m1, m3);
  long compared = 0;
  for (double t : {0.2, 0.5, 0.8}) {
    const SkinComplex complex = build_skin_complex(interpolated_balls(m1, m3, live, t), {0.5});
    for (const Eigen::Vector3d& x : points_between(m1, m3, t, 500, 23)) {
      const MorphOracleResult plain = morph.evaluate(x, t);
      REQUIRE(plain.certified);
      std::vector<BallPair> cell_pairs;
      for (int k : complex.cell(complex.locate(x)).balls)
        if (k >= 0) cell_pairs.push_back(live[static_cast<size_t>(k)]);
      for (const std::vector<BallPair>& start : {cell_pairs, std::vector<BallPair>{live.back()}, std::vector<BallPair>{}}) {
        const MorphOracleResult o = morph.evaluate(x, t, start);
        INFO("t = " << t << ", " << start.size() << " start pairs");
        CHECK(o.certified);
        CHECK(std::abs(o.value - plain.value) <= 1e-12 * (1 + std::abs(plain.value)));
        CHECK((o.gradient - plain.gradient).norm() <= 1e-10 * (1 + plain.gradient.norm()));
        ++compared;
      }
    }
  }
  CHECK(compared == 3 * 500 * 3);
  CHECK_THROWS_AS(morph.evaluate(Eigen::Vector3d::Zero(), 0.5, {BallPair{static_cast<int>(m1.size()), 0}}), ContractError);
}

namespace {

// Points on the skin of `balls`, by bisection of the skin oracle's sign along
// rays out of each ball's centre (a centre inside the skin to a point 4 A
// beyond its sphere, outside when the ray leaves the molecule).
std::vector<Eigen::Vector3d> points_on_skin(const std::vector<Ball>& balls, int rays_per_ball, unsigned seed) {
  const SkinOracle oracle(balls, 0.5);
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0, 1);
  std::vector<Eigen::Vector3d> points;
  for (const Ball& b : balls)
    for (int k = 0; k < rays_per_ball; ++k) {
      const Eigen::Vector3d d = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
      Eigen::Vector3d inside = b.center, outside = b.center + (std::sqrt(std::max(b.weight, 0.0)) + 4) * d;
      if (!(oracle.evaluate(inside).value < 0) || !(oracle.evaluate(outside).value > 0)) continue;
      for (int step = 0; step < 60; ++step) {
        const Eigen::Vector3d mid = 0.5 * (inside + outside);
        (oracle.evaluate(mid).value < 0 ? inside : outside) = mid;
      }
      points.push_back(0.5 * (inside + outside));
    }
  return points;
}

}  // namespace

// Issue 39 #1: within about 1e-5 of t = 0 the pair balls b_ij(t) of one source
// ball differ by t |z_j - z_j'|, and the solve over pairs missed the minimum
// on 1-2% of the skin's points (KKT gap past 1e-9: uncertified). Every point
// must be certified there, agree with the skin oracle of B(t)'s live pairs
// where that one certifies, and move continuously from the end's own skin.
TEST_CASE("morph oracle: points next to t = 0 and 1, where pair balls nearly coincide, are certified", "[oracle][morph]") {
  const auto pept = test::centred_model(test::data_file("pept.pdb"), 1);
  const auto al1 = test::centred_model(test::data_file("3al1.pdb"), 1);
  const MorphOracle morph(pept, al1, 0.5);
  const std::vector<BallPair> live = live_pairs(pept, al1);
  const std::vector<Eigen::Vector3d> on_source = points_on_skin(pept, 12, 5), on_target = points_on_skin(al1, 4, 6);
  REQUIRE(on_source.size() > 500);
  REQUIRE(on_target.size() > 500);
  for (double t : {1e-6, 3e-6, 1 - 1e-6, 1 - 3e-6}) {
    INFO("t = " << t);
    const bool near_source = t < 0.5;
    const SkinOracle end(near_source ? pept : al1, 0.5);
    const SkinOracle frame(interpolated_balls(pept, al1, live, t), 0.5);
    long uncertified = 0, compared = 0;
    for (const Eigen::Vector3d& x : near_source ? on_source : on_target) {
      const MorphOracleResult m = morph.evaluate(x, t);
      uncertified += !m.certified;
      CHECK(std::abs(m.value - end.evaluate(x).value) <= 1e-2 * std::min(t, 1 - t) / 1e-6);
      const OracleResult o = frame.evaluate(x);
      if (!o.certified) continue;
      ++compared;
      CHECK(std::abs(m.value - o.value) <= 1e-9 * std::max(1.0, std::abs(o.value)));
    }
    CHECK(uncertified == 0);
    CHECK(compared > 0);
  }
}
