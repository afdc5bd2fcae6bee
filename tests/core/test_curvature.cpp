// Principal curvatures against closed forms: spheres and a two-ball neck.
#include "skinmesh/core/sizing.hpp"
#include "skinmesh/core/skin_complex.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

using namespace skinmesh;

TEST_CASE("a lone ball's skin has curvature 1/radius", "[curvature]") {
  for (double s : {0.3, 0.5, 0.7}) {
    const double w = 3.0;
    const SkinComplex sc = build_skin_complex({{{0, 0, 0}, w}}, {s});
    const double radius = std::sqrt(s * w);
    const Eigen::Vector3d x = Eigen::Vector3d(1, 2, -0.5).normalized() * radius;
    const PrincipalCurvatures pc = sc.curvature(x, sc.locate(x));
    CHECK(pc.k1 == Approx(1 / radius).epsilon(1e-12));
    CHECK(pc.k2 == Approx(1 / radius).epsilon(1e-12));
    CHECK(local_length(sc, x, sc.locate(x)) == Approx(radius).epsilon(1e-12));
    CHECK(sc.max_abs_curvature(x, sc.locate(x)) == Approx(1 / radius).epsilon(1e-12));
  }
}

TEST_CASE("a void between four balls is a concave sphere", "[curvature]") {
  // Four balls on a regular tetrahedron around a small void: the tetrahedron
  // cell's patch is a sphere about z_X with radius sqrt((1-s) R2), curvature -1/r.
  // R2 = 3a^2 - w = 0.5 gives radius 0.5, inside the shrunk tetrahedron
  // (1-s) delta_X, whose inradius is (1-s) a sqrt(3) / 3 = 0.577.
  const double s = 0.5, a = 2.0, w = 11.5;
  const std::vector<Ball> balls = {{{a, a, a}, w}, {{a, -a, -a}, w}, {{-a, a, -a}, w}, {{-a, -a, a}, w}};
  const SkinComplex sc = build_skin_complex(balls, {s});
  const double R2 = 3 * a * a - w;  // orthogonal sphere about the origin
  const double radius = std::sqrt((1 - s) * R2);
  const Eigen::Vector3d x = Eigen::Vector3d(0.3, -0.2, 1).normalized() * radius;
  const int cell = sc.locate(x);
  REQUIRE(sc.cell(cell).dim == 3);
  CHECK(std::abs(sc.value(x)) < 1e-12);
  const PrincipalCurvatures pc = sc.curvature(x, cell);
  CHECK(pc.k1 == Approx(-1 / radius).epsilon(1e-12));
  CHECK(pc.k2 == Approx(-1 / radius).epsilon(1e-12));
  CHECK(sc.max_abs_curvature(x, cell) == Approx(1 / radius).epsilon(1e-12));
}

TEST_CASE("a two-ball neck has the hyperboloid's principal curvatures", "[curvature]") {
  // Two equal balls on the x axis. The edge cell's skin is the hyperboloid of
  // revolution (1-s) rho^2 - s t^2 + s(1-s) R2 = 0 (rho: distance from the axis,
  // t: axial offset from z_X), i.e. rho(t) = sqrt(a t^2 + b) with a = s/(1-s),
  // b = -s R2. As a surface of revolution its curvatures are
  //   parallel:  1 / (rho sqrt(1 + rho'^2)),  meridian: -rho'' / (1 + rho'^2)^(3/2).
  for (double s : {0.5, 0.3}) {
    const double w = 4.0, half = 1.2;
    const SkinComplex sc = build_skin_complex({{{-half, 0, 0}, w}, {{half, 0, 0}, w}}, {s});
    const double R2 = half * half - w;  // sphere orthogonal to both, centred at the origin
    REQUIRE(R2 < 0);
    const double a = s / (1 - s), b = -s * R2;
    for (double t : {0.0, 0.05, 0.1, 0.2}) {
      const double rho = std::sqrt(a * t * t + b);
      const double d1 = a * t / rho;                  // rho'
      const double d2 = a * b / (rho * rho * rho);    // rho''
      const double parallel = 1 / (rho * std::sqrt(1 + d1 * d1));
      const double meridian = -d2 / std::pow(1 + d1 * d1, 1.5);
      const Eigen::Vector3d x(t, rho * std::cos(0.7), rho * std::sin(0.7));
      const int cell = sc.locate(x);
      INFO("s = " << s << ", t = " << t);
      REQUIRE(sc.cell(cell).dim == 1);
      CHECK(std::abs(sc.value(x)) < 1e-12);
      const PrincipalCurvatures pc = sc.curvature(x, cell);
      CHECK(pc.k1 == Approx(parallel).epsilon(1e-10));
      CHECK(pc.k2 == Approx(meridian).epsilon(1e-10));
      CHECK(sc.max_abs_curvature(x, cell) ==
            Approx(std::max(std::abs(parallel), std::abs(meridian))).epsilon(1e-10));
      CHECK(std::abs(pc.d2.dot(Eigen::Vector3d::UnitX())) == Approx(1 / std::sqrt(1 + d1 * d1)).epsilon(1e-9));
    }
  }
}

TEST_CASE("a three-ball triangle cell has the two-sheet hyperboloid's principal curvatures", "[curvature]") {
  // Three equal balls on a circle of radius d about the origin in the xy
  // plane, overlapping in common (R2 = d^2 - w < 0). In the triangle cell
  // the skin is (1-s) t^2 - s rho^2 + s(1-s) R2 = 0 (t: height over the
  // plane, rho: distance from the axis through z_X = 0), i.e.
  // G = t^2 - a rho^2 + s R2 = 0 with a = s/(1-s): a surface of revolution
  // about the z axis. Its curvatures, from G's gradient and Hessian:
  //   parallel:  a / sqrt(a^2 rho^2 + t^2),
  //   meridian:  a s |R2| / (a^2 rho^2 + t^2)^(3/2).
  const double d = 2.0, w = 5.0, R2 = d * d - w;
  std::vector<Ball> balls;
  for (int k = 0; k < 3; ++k)
    balls.push_back({{d * std::cos(2 * M_PI * k / 3), d * std::sin(2 * M_PI * k / 3), 0}, w});
  for (double s : {0.5, 0.3}) {
    const SkinComplex sc = build_skin_complex(balls, {s});
    const double a = s / (1 - s);
    for (double rho : {0.0, 0.1, 0.25}) {
      const double t = std::sqrt(a * rho * rho - s * R2);
      const Eigen::Vector3d x(rho * std::cos(0.4), rho * std::sin(0.4), t);
      const int cell = sc.locate(x);
      INFO("s = " << s << ", rho = " << rho);
      REQUIRE(sc.cell(cell).dim == 2);
      CHECK(std::abs(sc.value(x)) < 1e-12);
      const double q = a * a * rho * rho + t * t;
      const double parallel = a / std::sqrt(q), meridian = a * s * std::abs(R2) / std::pow(q, 1.5);
      const PrincipalCurvatures pc = sc.curvature(x, cell);
      CHECK(std::max(std::abs(pc.k1), std::abs(pc.k2)) == Approx(std::max(parallel, meridian)).epsilon(1e-10));
      CHECK(std::min(std::abs(pc.k1), std::abs(pc.k2)) == Approx(std::min(parallel, meridian)).epsilon(1e-10));
      CHECK(sc.max_abs_curvature(x, cell) == Approx(std::max(parallel, meridian)).epsilon(1e-10));
    }
  }
}

TEST_CASE("target size follows curvature and respects its clamps", "[curvature][sizing]") {
  const SkinComplex sc = build_skin_complex({{{0, 0, 0}, 2.0}}, {0.5});
  const Eigen::Vector3d x(1.0, 0, 0);  // radius sqrt(0.5*2) = 1
  SizingOptions o;
  o.epsilon = 0.3;
  CHECK(target_size(sc, x, sc.locate(x), o) == Approx(0.3));
  o.max_size = 0.2;
  CHECK(target_size(sc, x, sc.locate(x), o) == Approx(0.2));
  o.max_size = 3;
  o.min_size = 0.5;
  CHECK(target_size(sc, x, sc.locate(x), o) == Approx(0.5));
  CHECK(size_for_length(1.0, o) == target_size(sc, x, sc.locate(x), o));
  o.min_size = 0.05;
  CHECK(size_for_length(0.5, o) == Approx(0.15));
  CHECK(size_for_length(std::numeric_limits<double>::infinity(), o) == o.max_size);
}
