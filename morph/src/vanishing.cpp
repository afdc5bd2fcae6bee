#include "vanishing.hpp"

#include <algorithm>

namespace skinmesh::detail {
namespace {

// Per vertex: its component (by the triangles; -1 for a vertex no triangle uses).
std::vector<int> component_of_vertices(const SurfaceMesh& mesh, int& count) {
  std::vector<int> parent(mesh.vertices.size(), -1);
  auto root = [&](int v) {
    while (parent[static_cast<size_t>(v)] != v) {
      int& up = parent[static_cast<size_t>(v)];
      up = parent[static_cast<size_t>(up)];  // path halving
      v = up;
    }
    return v;
  };
  for (const auto& t : mesh.triangles)
    for (int v : t)
      if (parent[static_cast<size_t>(v)] < 0) parent[static_cast<size_t>(v)] = v;
  for (const auto& t : mesh.triangles)
    for (size_t k = 1; k < 3; ++k) {
      const int a = root(t[0]), b = root(t[k]);
      if (a != b) parent[static_cast<size_t>(a)] = b;
    }
  std::vector<int> label(mesh.vertices.size(), -1), component(mesh.vertices.size(), -1);
  count = 0;
  for (size_t v = 0; v < parent.size(); ++v) {
    if (parent[v] < 0) continue;
    const int r = root(static_cast<int>(v));
    if (label[static_cast<size_t>(r)] < 0) label[static_cast<size_t>(r)] = count++;
    component[v] = label[static_cast<size_t>(r)];
  }
  return component;
}

struct ComponentFacts {
  long vertices = 0, triangles = 0;
  bool stayed = false;  // a vertex stayed in its cell
};

}  // namespace

std::vector<char> vanishing_components(const SurfaceMesh& mesh, const std::vector<char>& stayed_in_cell,
                                       const std::vector<VanishingSphere>& spheres, std::vector<char>& found) {
  int count = 0;
  const std::vector<int> component = component_of_vertices(mesh, count);
  std::vector<ComponentFacts> facts(static_cast<size_t>(count));
  for (size_t v = 0; v < component.size(); ++v) {
    if (component[v] < 0) continue;
    ComponentFacts& c = facts[static_cast<size_t>(component[v])];
    ++c.vertices;
    c.stayed = c.stayed || stayed_in_cell[v];
  }
  for (const auto& t : mesh.triangles) ++facts[static_cast<size_t>(component[static_cast<size_t>(t[0])])].triangles;
  std::vector<char> taken(static_cast<size_t>(count), 0), drop(mesh.vertices.size(), 0);
  found.assign(spheres.size(), 0);
  for (size_t k = 0; k < spheres.size(); ++k) {
    // Components with a vertex beyond the reach are out.
    std::vector<char> within(static_cast<size_t>(count), 1);
    for (size_t v = 0; v < component.size(); ++v)
      if (component[v] >= 0 && (mesh.vertices[v] - spheres[k].center).norm() > spheres[k].reach)
        within[static_cast<size_t>(component[v])] = 0;
    int candidate = -1, candidates = 0;
    for (int c = 0; c < count; ++c) {
      const ComponentFacts& f = facts[static_cast<size_t>(c)];
      // Closed: E = 3F/2, so the Euler characteristic is V - F/2.
      const bool sphere = 2 * f.vertices - f.triangles == 4;
      if (within[static_cast<size_t>(c)] && sphere && !f.stayed && !taken[static_cast<size_t>(c)]) {
        candidate = c;
        ++candidates;
      }
    }
    if (candidates != 1) continue;
    taken[static_cast<size_t>(candidate)] = 1;
    found[k] = 1;
  }
  for (size_t v = 0; v < component.size(); ++v)
    if (component[v] >= 0 && taken[static_cast<size_t>(component[v])]) drop[v] = 1;
  return drop;
}

}  // namespace skinmesh::detail
