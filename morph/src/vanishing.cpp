#include "vanishing.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <unordered_map>

namespace skinmesh::detail {
namespace {

// A component of the mesh lies wholly within a sphere's reach exactly when
// its triangles all do and none of them has a corner beyond it. Only the
// triangles with a corner within some sphere's reach are looked at (found
// in one parallel pass over the frame), so a step's cost beyond that pass
// is what lies near its events, not a labelling of the whole frame.
std::vector<int> triangles_near(const SurfaceMesh& mesh, const std::vector<VanishingSphere>& spheres) {
  std::vector<char> near(mesh.vertices.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, near.size(), 8192), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v)
      for (const VanishingSphere& s : spheres)
        if ((mesh.vertices[v] - s.center).norm() <= s.reach) {
          near[v] = 1;
          break;
        }
  });
  std::vector<int> out;
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    if (near[static_cast<size_t>(t[0])] || near[static_cast<size_t>(t[1])] || near[static_cast<size_t>(t[2])])
      out.push_back(static_cast<int>(f));
  }
  return out;
}

// The triangles of `near` wholly within the sphere's reach, and those with
// corners on both sides.
struct Split {
  std::vector<int> inside, straddling;
};

Split split_by(const SurfaceMesh& mesh, const std::vector<int>& near, const VanishingSphere& sphere) {
  Split out;
  for (int f : near) {
    int within = 0;
    for (int v : mesh.triangles[static_cast<size_t>(f)])
      within += (mesh.vertices[static_cast<size_t>(v)] - sphere.center).norm() <= sphere.reach;
    if (within == 3) out.inside.push_back(f);
    else if (within > 0) out.straddling.push_back(f);
  }
  return out;
}

// Union-find over the vertices of some triangles, by a map from vertex to
// a dense index (the triangles near a sphere are a few of the frame's).
class LocalComponents {
 public:
  int index(int v) {
    const auto [it, added] = dense_.emplace(v, static_cast<int>(parent_.size()));
    if (added) parent_.push_back(it->second);
    return it->second;
  }
  int find_vertex(int v) const {
    const auto it = dense_.find(v);
    return it == dense_.end() ? -1 : root(it->second);
  }
  int root(int i) const {
    while (parent_[static_cast<size_t>(i)] != i) {
      int& up = parent_[static_cast<size_t>(i)];
      up = parent_[static_cast<size_t>(up)];  // path halving
      i = up;
    }
    return i;
  }
  void join(int a, int b) {
    a = root(a);
    b = root(b);
    if (a != b) parent_[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
  }
  size_t size() const { return parent_.size(); }
  const std::unordered_map<int, int>& dense() const { return dense_; }

 private:
  std::unordered_map<int, int> dense_;
  mutable std::vector<int> parent_;  // halved by root
};

// The vertices of the one component `near` holds wholly within the sphere
// that is a sphere itself and none of whose vertices stayed in its cell or
// is marked in `taken`; empty when there is no such component or more
// than one.
std::vector<int> vanishing_component(const SurfaceMesh& mesh, const Split& near,
                                     const std::vector<char>& stayed_in_cell, const std::vector<char>& taken) {
  LocalComponents parts;
  for (int f : near.inside) {
    const auto& t = mesh.triangles[static_cast<size_t>(f)];
    const int a = parts.index(t[0]);
    parts.join(a, parts.index(t[1]));
    parts.join(a, parts.index(t[2]));
  }
  // Per root: vertices, triangles, and whether it is out (a vertex stayed
  // in its cell or is taken, or a triangle of it reaches beyond the sphere).
  std::vector<long> vertices(parts.size(), 0), triangles(parts.size(), 0);
  std::vector<char> out(parts.size(), 0);
  for (const auto& [v, i] : parts.dense()) {
    const auto r = static_cast<size_t>(parts.root(i));
    ++vertices[r];
    if (stayed_in_cell[static_cast<size_t>(v)] || taken[static_cast<size_t>(v)]) out[r] = 1;
  }
  for (int f : near.inside) {
    const int corner = mesh.triangles[static_cast<size_t>(f)][0];
    ++triangles[static_cast<size_t>(parts.find_vertex(corner))];
  }
  for (int f : near.straddling)
    for (int v : mesh.triangles[static_cast<size_t>(f)]) {
      const int r = parts.find_vertex(v);
      if (r >= 0) out[static_cast<size_t>(r)] = 1;
    }
  int candidate = -1, candidates = 0;
  for (size_t r = 0; r < parts.size(); ++r) {
    if (parts.root(static_cast<int>(r)) != static_cast<int>(r) || out[r]) continue;
    // Closed: E = 3F/2, so the Euler characteristic is V - F/2.
    if (2 * vertices[r] - triangles[r] != 4) continue;
    candidate = static_cast<int>(r);
    ++candidates;
  }
  std::vector<int> component;
  if (candidates != 1) return component;
  for (const auto& [v, i] : parts.dense())
    if (parts.root(i) == candidate) component.push_back(v);
  return component;
}

}  // namespace

std::vector<char> vanishing_components(const SurfaceMesh& mesh, const std::vector<char>& stayed_in_cell,
                                       const std::vector<VanishingSphere>& spheres, std::vector<char>& found) {
  std::vector<char> drop(mesh.vertices.size(), 0);
  found.assign(spheres.size(), 0);
  const std::vector<int> near_any_sphere = triangles_near(mesh, spheres);
  for (size_t k = 0; k < spheres.size(); ++k) {
    const std::vector<int> component =
        vanishing_component(mesh, split_by(mesh, near_any_sphere, spheres[k]), stayed_in_cell, drop);
    if (component.empty()) continue;
    found[k] = 1;
    for (int v : component) drop[static_cast<size_t>(v)] = 1;
  }
  return drop;
}

}  // namespace skinmesh::detail
