// Items placed at points, hashed into cubic cells of one width, for the
// question "which items lie within r of p" when r spans a few cells: a
// lookup scans the cells around p's. Used by the mesher's patch mode (how
// near the patch a crossing is), whose items arrive one by one; a fixed
// set is better served by CellGrid (cell_grid.hpp).
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

namespace skinmesh {

template <class Item>
class PointGrid {
 public:
  explicit PointGrid(double cell = 1.0) : cell_(cell) {}  // Angstrom, > 0
  double cell() const { return cell_; }
  bool empty() const { return cells_.empty(); }
  void insert(const Eigen::Vector3d& p, Item item) { cells_[key(cell_of(p))].push_back(std::move(item)); }
  // Calls visit(item) for every item in the cells within `span` cells of
  // p's (a superset of the items within span * cell() of p) until visit
  // returns true; returns whether one did.
  template <class Visit>
  bool any_near(const Eigen::Vector3d& p, int span, Visit visit) const {
    const Eigen::Vector3i c = cell_of(p);
    for (int i = -span; i <= span; ++i)
      for (int j = -span; j <= span; ++j)
        for (int k = -span; k <= span; ++k) {
          const auto it = cells_.find(key(c + Eigen::Vector3i(i, j, k)));
          if (it == cells_.end()) continue;
          for (const Item& item : it->second)
            if (visit(item)) return true;
        }
    return false;
  }

 private:
  Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const { return (p / cell_).array().floor().cast<int>(); }
  static int64_t key(const Eigen::Vector3i& c) {  // 21 bits a coordinate
    return (int64_t{c.x()} & 0x1FFFFF) | ((int64_t{c.y()} & 0x1FFFFF) << 21) | ((int64_t{c.z()} & 0x1FFFFF) << 42);
  }
  double cell_;
  std::unordered_map<int64_t, std::vector<Item>> cells_;
};

}  // namespace skinmesh
