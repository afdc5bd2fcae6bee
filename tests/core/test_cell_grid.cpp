// The dense cell grid against a pass over every point: what a query visits
// holds every point within the cube, nothing twice, and the counts agree.
#include "skinmesh/core/cell_grid.hpp"
#include "skinmesh/core/error.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <set>

using namespace skinmesh;

namespace {

std::vector<Eigen::Vector3d> random_points(size_t n, double spread, std::mt19937& random) {
  std::uniform_real_distribution<double> u(-spread, spread);
  std::vector<Eigen::Vector3d> points(n);
  for (auto& p : points) p = {u(random), u(random), u(random)};
  return points;
}

bool in_cube(const Eigen::Vector3d& p, const Eigen::Vector3d& x, double r) {
  return ((p - x).cwiseAbs().array() <= r).all();
}

}  // namespace

TEST_CASE("a cell grid visits every point in a query cube, each once, with its id and position", "[grid]") {
  std::mt19937 random(7);
  const std::vector<Eigen::Vector3d> points = random_points(2000, 20.0, random);
  std::vector<int> ids(points.size());
  for (size_t k = 0; k < ids.size(); ++k) ids[k] = 3 * static_cast<int>(k) + 1;
  CellGridOptions options;
  options.cell = 1.5;
  options.counts = true;
  const CellGrid grid(points, ids, Eigen::AlignedBox3d(), options);
  REQUIRE(grid.size() == points.size());
  std::uniform_real_distribution<double> where(-30.0, 30.0), radius(0.0, 12.0);
  for (int query = 0; query < 300; ++query) {
    const Eigen::Vector3d x(where(random), where(random), where(random));
    const double r = radius(random);
    std::multiset<int> seen;
    grid.each_near(x, r, [&](int id, const Eigen::Vector3d& p) {
      REQUIRE(id % 3 == 1);
      CHECK(p == points[static_cast<size_t>(id / 3)]);
      seen.insert(id);
    });
    for (size_t k = 0; k < points.size(); ++k)
      if (in_cube(points[k], x, r)) CHECK(seen.count(ids[k]) == 1);
    for (int id : seen) CHECK(seen.count(id) == 1);
    const std::optional<CellGrid::Cells> cells = grid.cells_met(x, r);
    CHECK(static_cast<size_t>(cells ? grid.count_in(*cells) : 0) == seen.size());
  }
}

TEST_CASE("a cell grid stops at the first point a visit accepts", "[grid]") {
  std::mt19937 random(11);
  const std::vector<Eigen::Vector3d> points = random_points(500, 10.0, random);
  CellGridOptions options;
  options.cell = 2.0;
  const CellGrid grid(points, {}, Eigen::AlignedBox3d(), options);
  const Eigen::Vector3d x(1, -2, 3);
  int visited = 0;
  const bool found = grid.any_near(x, 6.0, [&](int k, const Eigen::Vector3d&) {
    ++visited;
    return (points[static_cast<size_t>(k)] - x).norm() < 6.0;
  });
  CHECK(found);
  int inside = 0;
  for (const auto& p : points) inside += (p - x).norm() < 6.0;
  CHECK(inside > 1);
  CHECK(visited < static_cast<int>(points.size()));
  CHECK_FALSE(grid.any_near(x, 6.0, [](int, const Eigen::Vector3d&) { return false; }));
}

TEST_CASE("a cell grid widens its cells to its bound and answers far, huge and NaN queries", "[grid]") {
  std::mt19937 random(13);
  // Two clusters a kilometre apart: at 0.1 A cells the box would hold 10^15.
  std::vector<Eigen::Vector3d> points = random_points(100, 1.0, random);
  for (size_t k = 0; k < 50; ++k) points[k].x() += 1e4;
  CellGridOptions options;
  options.cell = 0.1;
  options.most_cells = 4.0 * static_cast<double>(points.size()) + 64;
  options.counts = true;
  const CellGrid grid(points, {}, Eigen::AlignedBox3d(), options);
  CHECK(grid.cells() <= options.most_cells);
  CHECK(grid.cell() > 0.1);
  size_t all = 0;
  grid.each_near(Eigen::Vector3d(5e3, 0, 0), 1e300, [&](int, const Eigen::Vector3d&) { ++all; });
  CHECK(all == points.size());
  CHECK_FALSE(grid.cells_met(Eigen::Vector3d(-1e5, 0, 0), 10.0));
  CHECK_FALSE(grid.cells_met(Eigen::Vector3d(NAN, 0, 0), 1.0));
  CHECK_FALSE(grid.cells_met(Eigen::Vector3d::Zero(), NAN));
  CHECK_FALSE(grid.cells_met(Eigen::Vector3d::Zero(), -1.0));
  CHECK(grid.count_in(*grid.cells_met(Eigen::Vector3d(1e4, 0, 0), 2.0)) == 50);
  CHECK_THROWS_AS(CellGrid({Eigen::Vector3d(NAN, 0, 0)}, {}, Eigen::AlignedBox3d(), options), ContractError);
}
