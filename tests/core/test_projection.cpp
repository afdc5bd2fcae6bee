// Projection onto the skin and segment-skin crossings, judged by the oracle.
#include "test_support.hpp"

#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_oracle.hpp"

#include <catch2/catch.hpp>

#include <random>

using namespace skinmesh;

namespace {

struct Fixture {
  std::vector<Ball> balls;
  SkinComplex complex;
  SkinOracle oracle;
  explicit Fixture(const std::string& path, double s = 0.5)
      : balls(balls_from_molecule(read_molecule(path), s)), complex(build_skin_complex(balls, {s})), oracle(balls, s) {}
};

// Exact skin points from the oracle alone: along a ray from a ball centre
// (inside the body), the first sign change of F, refined by bisection.
std::vector<Eigen::Vector3d> oracle_skin_points(const Fixture& f, int count, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_int_distribution<size_t> pick(0, f.balls.size() - 1);
  std::vector<Eigen::Vector3d> points;
  while (static_cast<int>(points.size()) < count) {
    const Ball& b = f.balls[pick(rng)];
    const Eigen::Vector3d u = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    double lo = 0, hi = 0.05;
    while (hi < 20 && f.oracle.evaluate(b.center + hi * u).value < 0) lo = hi, hi += 0.05;
    for (int k = 0; k < 60; ++k) {
      const double mid = 0.5 * (lo + hi);
      (f.oracle.evaluate(b.center + mid * u).value < 0 ? lo : hi) = mid;
    }
    points.push_back(b.center + 0.5 * (lo + hi) * u);
  }
  return points;
}

void check_projection(const std::string& path, unsigned seed) {
  Fixture f(path);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  long tried = 0, projected = 0, far = 0;
  double worst = 0, longest_move = 0;
  for (const Eigen::Vector3d& p : oracle_skin_points(f, 1500, seed)) {
    // A start within 1 A of the skin: a skin point plus an offset of length <= 1 A.
    const Eigen::Vector3d offset = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized() *
                                   std::cbrt(unit(rng));
    const Eigen::Vector3d x = p + offset;
    ++tried;
    const Projection proj = f.complex.project(x);
    if (!proj.converged) continue;
    ++projected;
    worst = std::max(worst, f.oracle.evaluate(proj.point).distance());
    longest_move = std::max(longest_move, (proj.point - x).norm());
    far += (proj.point - x).norm() > 1.0 + 1e-9;
  }
  INFO(path << ": " << projected << " of " << tried << " projected; worst oracle distance " << worst
            << " A, longest move " << longest_move << " A, " << far << " moves over 1 A");
  CHECK(projected == tried);
  CHECK(worst <= 1e-9);
  // The start was within 1 A of the skin, so its closest skin point is too. The
  // refinement finds a local closest point: nearly always the global one.
  CHECK(far * 200 <= tried);
  CHECK(longest_move <= 2.5);
}

// Every crossing the complex reports is on the skin by the oracle, and every
// sign change of the oracle along the segment (found by sampling, refined by
// bisection) is one of the reported crossings.
void check_segments(const std::string& path, unsigned seed) {
  Fixture f(path);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> length(0.3, 5.0);
  const auto starts = test::sample_near_balls(f.balls, 0.5, 300, 1.5, seed);
  long crossings = 0, oracle_crossings = 0, unmatched = 0;
  double worst_on_skin = 0, worst_match = 0;
  for (const Eigen::Vector3d& a : starts) {
    const Eigen::Vector3d dir = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    const double len = length(rng);
    const Eigen::Vector3d b = a + len * dir;
    const auto found = f.complex.intersect_segment(a, b);
    crossings += static_cast<long>(found.size());
    for (const SegmentCrossing& c : found) worst_on_skin = std::max(worst_on_skin, f.oracle.evaluate(c.point).distance());

    const int samples = 400;
    auto F = [&](double t) { return f.oracle.evaluate(a + t * (b - a)).value; };
    double t0 = 0, f0 = F(0);
    for (int i = 1; i <= samples; ++i) {
      const double t1 = static_cast<double>(i) / samples, f1 = F(t1);
      if ((f0 < 0) != (f1 < 0)) {
        double lo = t0, hi = t1, flo = f0;
        for (int k = 0; k < 60 && (hi - lo) * len > 1e-13; ++k) {
          const double mid = 0.5 * (lo + hi), fm = F(mid);
          if ((fm < 0) == (flo < 0)) lo = mid, flo = fm; else hi = mid;
        }
        const double root = 0.5 * (lo + hi);
        ++oracle_crossings;
        double best = INFINITY;
        for (const SegmentCrossing& c : found) best = std::min(best, std::abs(c.t - root) * len);
        if (best > 1e-9) ++unmatched;
        else worst_match = std::max(worst_match, best);
      }
      t0 = t1, f0 = f1;
    }
  }
  INFO(path << ": " << crossings << " crossings reported, " << oracle_crossings << " found by bisection; worst "
            << worst_on_skin << " A off the skin; worst match " << worst_match << " A");
  CHECK(oracle_crossings >= 100);
  CHECK(unmatched == 0);
  CHECK(crossings >= oracle_crossings);
  CHECK(worst_on_skin <= 1e-9);
}

}  // namespace

TEST_CASE("projection lands on the skin: pept", "[projection]") { check_projection(test::data_file("pept.pdb"), 31); }
TEST_CASE("projection lands on the skin: 3al1", "[projection]") { check_projection(test::data_file("3al1.pdb"), 32); }
TEST_CASE("projection lands on the skin: 1ubi", "[projection]") { check_projection(test::data_file("1ubi.pdb"), 33); }

TEST_CASE("segment crossings agree with bisection on the oracle: pept", "[segment]") {
  check_segments(test::data_file("pept.pdb"), 41);
}
TEST_CASE("segment crossings agree with bisection on the oracle: 1ubi", "[segment]") {
  check_segments(test::data_file("1ubi.pdb"), 42);
}

TEST_CASE("segment through one ball crosses twice at the sphere", "[segment]") {
  const double s = 0.5, w = 8.0;
  const SkinComplex sc = build_skin_complex({{{0, 0, 0}, w}}, {s});
  const auto found = sc.intersect_segment({-5, 0, 0}, {5, 0, 0});
  REQUIRE(found.size() == 2);
  CHECK(found[0].entering);
  CHECK_FALSE(found[1].entering);
  CHECK(std::abs(found[0].point.x() + 2.0) < 1e-12);
  CHECK(std::abs(found[1].point.x() - 2.0) < 1e-12);
}
