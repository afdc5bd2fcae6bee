// Disjoint sets over 0..n-1 (union-find with path halving): the components
// of a mesh, the fans around a vertex, the pieces and voids of a complex.
// The root of a set is its least element, whatever order its pairs were
// joined in.
#pragma once

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <vector>

namespace skinmesh {

template <class Index = int>
class UnionFind {
 public:
  explicit UnionFind(size_t n = 0) { reset(n); }
  // n singletons again, keeping the storage.
  void reset(size_t n) {
    parent_.resize(n);
    std::iota(parent_.begin(), parent_.end(), Index{0});
  }
  size_t size() const { return parent_.size(); }
  Index find(Index x) {
    while (parent_[static_cast<size_t>(x)] != x)
      x = parent_[static_cast<size_t>(x)] = parent_[static_cast<size_t>(parent_[static_cast<size_t>(x)])];
    return x;
  }
  // Joins the sets of a and b under the lesser root; whether they were apart.
  bool unite(Index a, Index b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    parent_[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
    return true;
  }

 private:
  std::vector<Index> parent_;
};

}  // namespace skinmesh
