#include "skinmesh/core/cell_grid.hpp"

#include "skinmesh/core/error.hpp"

#include <algorithm>
#include <cmath>

namespace skinmesh {

namespace {

// Whatever the options say: an int per cell, twice with counts.
constexpr double kMostCellsEver = double{1 << 24};

double cells_at(const Eigen::Vector3d& extent, double width) {
  double cells = 1;
  for (int k = 0; k < 3; ++k) cells *= std::floor(extent[k] / width) + 1;
  return cells;
}

}  // namespace

CellGrid::CellGrid(std::vector<Eigen::Vector3d> points, std::vector<int> ids, Eigen::AlignedBox3d box,
                   const CellGridOptions& options)
    : cell_(options.cell) {
  if (!(cell_ > 0) || !std::isfinite(cell_)) contract_error("CellGrid: the cell width must be positive and finite");
  if (!ids.empty() && ids.size() != points.size()) contract_error("CellGrid: points and ids do not match");
  for (const Eigen::Vector3d& p : points) {
    if (!p.allFinite()) contract_error("CellGrid: a point is not finite");
    box.extend(p);
  }
  if (box.isEmpty()) box.extend(Eigen::Vector3d::Zero());
  origin_ = box.min();
  const Eigen::Vector3d extent = box.sizes();
  const double most = std::clamp(options.most_cells, 1.0, kMostCellsEver);
  while (cells_at(extent, cell_) > most) cell_ *= 1.5;
  dims_ = (extent / cell_).array().floor().cast<int>() + 1;
  first_.assign(static_cast<size_t>(dims_.prod()) + 1, 0);
  std::vector<size_t> cell_of_point(points.size());
  for (size_t k = 0; k < points.size(); ++k) ++first_[(cell_of_point[k] = index(cell_of(points[k]))) + 1];
  for (size_t c = 1; c < first_.size(); ++c) first_[c] += first_[c - 1];
  items_.resize(points.size());
  points_.resize(points.size());
  std::vector<int> fill(first_.begin(), first_.end() - 1);
  for (size_t k = 0; k < points.size(); ++k) {
    const auto q = static_cast<size_t>(fill[cell_of_point[k]]++);
    items_[q] = ids.empty() ? static_cast<int>(k) : ids[k];
    points_[q] = points[k];
  }
  if (options.counts) sum_counts();
}

Eigen::Vector3i CellGrid::cell_of(const Eigen::Vector3d& p) const {
  const Eigen::Vector3i c = ((p - origin_) / cell_).array().floor().cast<int>();
  return c.cwiseMax(0).cwiseMin(dims_ - Eigen::Vector3i::Ones());
}

// Clamped in floating point before the cast: a far point or a huge radius
// must not overflow the integer.
std::optional<CellGrid::Cells> CellGrid::cells_met(const Eigen::Vector3d& x, double r) const {
  Cells cells;
  for (int k = 0; k < 3; ++k) {
    const double low = std::floor((x[k] - r - origin_[k]) / cell_), high = std::floor((x[k] + r - origin_[k]) / cell_);
    const double last = dims_[k] - 1;
    if (!(high >= 0 && low <= last && low <= high)) return std::nullopt;
    cells.low[k] = static_cast<int>(std::max(low, 0.0));
    cells.high[k] = static_cast<int>(std::min(high, last));
  }
  return cells;
}

void CellGrid::sum_counts() {
  const Eigen::Vector3i d = dims_ + Eigen::Vector3i::Ones();
  sums_.assign(static_cast<size_t>(d.prod()), 0);
  const auto at = [&](int i, int j, int k) -> int& { return sums_[sum_index(i, j, k)]; };
  for (int i = 1; i < d.x(); ++i)
    for (int j = 1; j < d.y(); ++j)
      for (int k = 1; k < d.z(); ++k) {
        const size_t c = index({i - 1, j - 1, k - 1});
        at(i, j, k) = (first_[c + 1] - first_[c]) + at(i - 1, j, k) + at(i, j - 1, k) + at(i, j, k - 1) -
                      at(i - 1, j - 1, k) - at(i - 1, j, k - 1) - at(i, j - 1, k - 1) + at(i - 1, j - 1, k - 1);
      }
}

size_t CellGrid::sum_index(int i, int j, int k) const {
  return (static_cast<size_t>(i) * static_cast<size_t>(dims_.y() + 1) + static_cast<size_t>(j)) *
             static_cast<size_t>(dims_.z() + 1) +
         static_cast<size_t>(k);
}

int CellGrid::sum(int i, int j, int k) const { return sums_[sum_index(i, j, k)]; }

// Inclusion-exclusion over the summed table's eight corners.
int CellGrid::count_in(const Cells& cells) const {
  if (sums_.empty()) contract_error("CellGrid::count_in needs a grid built with counts");
  const int a0 = cells.low.x(), a1 = cells.low.y(), a2 = cells.low.z();
  const int b0 = cells.high.x() + 1, b1 = cells.high.y() + 1, b2 = cells.high.z() + 1;
  return sum(b0, b1, b2) - sum(a0, b1, b2) - sum(b0, a1, b2) - sum(b0, b1, a2) + sum(a0, a1, b2) + sum(a0, b1, a2) +
         sum(b0, a1, a2) - sum(a0, a1, a2);
}

}  // namespace skinmesh
