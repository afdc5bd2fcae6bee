// Points sorted into cubic cells over a box by one counting sort: each
// cell's points in one run of one array, their positions beside them in the
// same order. For the question "which points lie near p" asked many times
// of one fixed set (the oracle's balls, a patch's neighbourhood, the atoms
// that moved): flat arrays, where a hash of cells would cost more to fill
// than the searches it serves. PointGrid (point_grid.hpp) is the one to
// use when points arrive one by one.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <limits>
#include <optional>
#include <vector>

namespace skinmesh {

struct CellGridOptions {
  double cell = 1.0;  // Angstrom (> 0): the cubes' width, before any widening
  // The cell widens by half again until the grid has at most this many
  // cells, so memory stays bounded however the points spread.
  double most_cells = std::numeric_limits<double>::infinity();
  bool counts = false;  // keep a summed table of the counts (count_in)
};

class CellGrid {
 public:
  // The cells met by a query cube, inclusive, clamped to the grid.
  struct Cells {
    Eigen::Vector3i low, high;
    double count() const { return (high - low + Eigen::Vector3i::Ones()).cast<double>().prod(); }
  };

  // Point k is item ids[k] (k itself when ids is empty). The grid covers
  // `box` grown to hold every point.
  CellGrid(std::vector<Eigen::Vector3d> points, std::vector<int> ids, Eigen::AlignedBox3d box,
           const CellGridOptions& options);

  double cell() const { return cell_; }
  double cells() const { return static_cast<double>(first_.size() - 1); }
  size_t size() const { return items_.size(); }

  // The cells that the cube of half-width r about x meets; none when it
  // misses the grid or x or r is not a number.
  std::optional<Cells> cells_met(const Eigen::Vector3d& x, double r) const;
  // How many points lie in those cells (needs options.counts).
  int count_in(const Cells& cells) const;

  // Calls visit(item, point) for every point in the cells, a row of cells
  // at a time, until it returns true; returns whether it did.
  template <class Visit>
  bool any_in(const Cells& cells, Visit visit) const {
    for (int i = cells.low.x(); i <= cells.high.x(); ++i)
      for (int j = cells.low.y(); j <= cells.high.y(); ++j)
        for (int q = first_[index({i, j, cells.low.z()})], end = first_[index({i, j, cells.high.z()}) + 1]; q < end;
             ++q)
          if (visit(items_[static_cast<size_t>(q)], points_[static_cast<size_t>(q)])) return true;
    return false;
  }
  // any_in over the cells the cube of half-width r about x meets: a
  // superset of the points within r of x.
  template <class Visit>
  bool any_near(const Eigen::Vector3d& x, double r, Visit visit) const {
    const std::optional<Cells> cells = cells_met(x, r);
    return cells && any_in(*cells, visit);
  }
  // Calls visit(item, point) for every point any_near would visit.
  template <class Visit>
  void each_near(const Eigen::Vector3d& x, double r, Visit visit) const {
    any_near(x, r, [&](int item, const Eigen::Vector3d& p) {
      visit(item, p);
      return false;
    });
  }

 private:
  size_t index(const Eigen::Vector3i& c) const {
    return (static_cast<size_t>(c.x()) * static_cast<size_t>(dims_.y()) + static_cast<size_t>(c.y())) *
               static_cast<size_t>(dims_.z()) +
           static_cast<size_t>(c.z());
  }
  Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const;
  void sum_counts();
  size_t sum_index(int i, int j, int k) const;  // in sums_, whose sides are dims_ + 1
  int sum(int i, int j, int k) const;

  Eigen::Vector3d origin_;
  double cell_;
  Eigen::Vector3i dims_;
  std::vector<int> first_;  // points of cell c: first_[c] .. first_[c + 1]
  std::vector<int> items_;
  std::vector<Eigen::Vector3d> points_;  // of items_, in their order: read together
  std::vector<int> sums_;                // sums_(i, j, k): the points in cells [0, i) x [0, j) x [0, k)
};

}  // namespace skinmesh
