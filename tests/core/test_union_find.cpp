// Union-find against labels spread by a pass over the joined pairs until
// nothing changes: the same sets, each rooted at its least element.
#include "skinmesh/core/union_find.hpp"

#include <catch2/catch.hpp>

#include <random>
#include <utility>
#include <vector>

using namespace skinmesh;

namespace {

// Per element, the least element of its set: every label starts as the
// element itself and each joined pair takes the lesser of its two labels.
std::vector<int> least_of_set(size_t n, const std::vector<std::pair<int, int>>& joined) {
  std::vector<int> label(n);
  for (size_t i = 0; i < n; ++i) label[i] = static_cast<int>(i);
  for (bool changed = true; changed;) {
    changed = false;
    for (const auto& [a, b] : joined) {
      int& la = label[static_cast<size_t>(a)];
      int& lb = label[static_cast<size_t>(b)];
      if (la != lb) {
        la = lb = std::min(la, lb);
        changed = true;
      }
    }
  }
  return label;
}

}  // namespace

TEST_CASE("union-find: the sets of the joined pairs, each rooted at its least element", "[core][union_find]") {
  std::mt19937 random(17);
  for (int round = 0; round < 50; ++round) {
    const size_t n = 1 + random() % 200;
    std::uniform_int_distribution<int> element(0, static_cast<int>(n) - 1);
    std::vector<std::pair<int, int>> joined(random() % (2 * n));
    UnionFind<> sets(n);
    long merges = 0;
    for (auto& [a, b] : joined) {
      a = element(random), b = element(random);
      merges += sets.unite(a, b);
    }
    const std::vector<int> least = least_of_set(n, joined);
    long roots = 0;
    for (size_t i = 0; i < n; ++i) {
      CHECK(sets.find(static_cast<int>(i)) == least[i]);
      roots += least[i] == static_cast<int>(i);
    }
    // Each merge that joined two sets took one away.
    CHECK(roots == static_cast<long>(n) - merges);
  }
  UnionFind<long> again(3);
  again.unite(2, 1);
  again.reset(3);
  CHECK(again.find(2) == 2);
}
