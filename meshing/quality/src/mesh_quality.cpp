// Grading a triangle mesh (see mesh_quality.hpp).
#include "skinmesh/quality/mesh_quality.hpp"

#include "skinmesh/core/union_find.hpp"
#include "skinmesh/core/vertex_stars.hpp"

#include <Eigen/Geometry>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace skinmesh {
namespace {

constexpr double kDegrees = 180.0 / M_PI;

uint64_t edge_key(int a, int b) {
  const auto lo = static_cast<uint64_t>(std::min(a, b)), hi = static_cast<uint64_t>(std::max(a, b));
  return (lo << 32) | hi;
}

// Per triangle: angles, radius-edge ratio, aspect, area, volume.
void grade_triangles(const SurfaceMesh& mesh, MeshQuality& q) {
  const auto& V = mesh.vertices;
  q.triangles = static_cast<long>(mesh.triangles.size());
  q.min_angle = 180;
  q.min_angle_histogram = {0, 60, std::vector<long>(12, 0)};
  double sum_min_angle = 0;
  long below20 = 0, below10 = 0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = V[t[0]];
    const Eigen::Vector3d& b = V[t[1]];
    const Eigen::Vector3d& c = V[t[2]];
    const double twice_area = (b - a).cross(c - a).norm();
    const double area = 0.5 * twice_area;
    q.area += area;
    q.volume += a.dot(b.cross(c)) / 6.0;
    const double la = (b - c).norm(), lb = (c - a).norm(), lc = (a - b).norm();
    const double shortest = std::min({la, lb, lc});
    // Every corner's angle is atan2(|u x v|, u . v) of its two edges u, v:
    // the same |u x v| (twice the area) at each, so the smallest angle is
    // at the corner of the largest dot product and the largest at the least.
    const double dots[3] = {(b - a).dot(c - a), (c - b).dot(a - b), (a - c).dot(b - c)};
    const double smallest = std::atan2(twice_area, std::max({dots[0], dots[1], dots[2]})) * kDegrees;
    q.min_angle = std::min(q.min_angle, smallest);
    q.max_angle = std::max(q.max_angle, std::atan2(twice_area, std::min({dots[0], dots[1], dots[2]})) * kDegrees);
    sum_min_angle += smallest;
    below20 += smallest < 20;
    below10 += smallest < 10;
    ++q.min_angle_histogram.counts[std::min<size_t>(11, static_cast<size_t>(smallest / 5.0))];
    if (area <= 0) {
      ++q.degenerate_triangles;
      q.max_radius_edge = q.max_aspect = INFINITY;
    } else {
      const double circumradius = la * lb * lc / (4 * area);
      const double inradius = 2 * area / (la + lb + lc);
      q.max_radius_edge = std::max(q.max_radius_edge, circumradius / shortest);
      q.max_aspect = std::max(q.max_aspect, circumradius / (2 * inradius));
    }
  }
  if (q.triangles) {
    q.mean_min_angle = sum_min_angle / q.triangles;
    q.share_below_20 = static_cast<double>(below20) / q.triangles;
    q.share_below_10 = static_cast<double>(below10) / q.triangles;
  }
}

// Every use of an edge as its key and direction (edge_key << 1 | used as
// min -> max; ids < 2^31), in ascending order: bucketed by the lower end
// (a counting sort), then each bucket (a dozen uses) sorted, in parallel.
std::vector<uint64_t> sorted_edge_uses(const SurfaceMesh& mesh) {
  std::vector<size_t> first(mesh.vertices.size() + 1, 0);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) ++first[static_cast<size_t>(std::min(t[k], t[(k + 1) % 3])) + 1];
  std::partial_sum(first.begin(), first.end(), first.begin());
  std::vector<uint64_t> uses(first.back());
  std::vector<size_t> fill(first.begin(), first.end() - 1);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      uses[fill[static_cast<size_t>(std::min(a, b))]++] = edge_key(a, b) << 1 | static_cast<uint64_t>(a < b);
    }
  tbb::parallel_for(tbb::blocked_range<size_t>(0, mesh.vertices.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v)
      std::sort(uses.begin() + static_cast<long>(first[v]), uses.begin() + static_cast<long>(first[v + 1]));
  });
  return uses;
}

// Edges: how many triangles use each, and in which directions, from their
// uses in order (sorted_edge_uses: the uses of one edge are neighbours; a
// hash map of the edges cost more than the rest of the grade).
void grade_edges(const SurfaceMesh& mesh, MeshQuality& q) {
  const auto& V = mesh.vertices;
  q.min_edge = INFINITY;
  const std::vector<uint64_t> uses = sorted_edge_uses(mesh);
  double sum_edge = 0;
  for (size_t first = 0, next = 0; first < uses.size(); first = next) {
    const uint64_t key = uses[first] >> 1;
    int count = 0, forward = 0;
    for (next = first; next < uses.size() && uses[next] >> 1 == key; ++next) {
      ++count;
      forward += static_cast<int>(uses[next] & 1u);
    }
    ++q.edges;
    const int a = static_cast<int>(key >> 32), b = static_cast<int>(key & 0xffffffffu);
    const double length = (V[a] - V[b]).norm();
    q.min_edge = std::min(q.min_edge, length);
    q.max_edge = std::max(q.max_edge, length);
    sum_edge += length;
    if (count == 1) ++q.boundary_edges;
    if (count > 2) ++q.nonmanifold_edges;
    if (count == 2 && forward != 1) ++q.inconsistent_edges;
  }
  if (q.edges) q.mean_edge = sum_edge / q.edges;
  if (!q.edges) q.min_edge = 0;
}

// Vertices: valence, and whether the triangles around each form one fan.
// The triangles around each vertex in one array; fans (a dozen triangles)
// joined by scans of small reused lists, no allocation per vertex.
void grade_vertices(const SurfaceMesh& mesh, MeshQuality& q) {
  const auto& T = mesh.triangles;
  const size_t n = mesh.vertices.size();
  const VertexStars stars(mesh);
  long used = 0;
  UnionFind<> fans_of;  // the triangles around one vertex, by their place in its star
  std::vector<std::pair<int, int>> first_with_other;  // other endpoint, local triangle
  for (size_t v = 0; v < n; ++v) {
    const int* fan = stars.begin(static_cast<int>(v));
    const int size = stars.size(static_cast<int>(v));
    if (size == 0) {
      ++q.unused_vertices;
      continue;
    }
    ++used;
    ++q.valence[size];
    // Fans: triangles around v joined when they share an edge through v.
    fans_of.reset(static_cast<size_t>(size));
    first_with_other.clear();
    for (int i = 0; i < size; ++i)
      for (int k = 0; k < 3; ++k) {
        const int w = T[static_cast<size_t>(fan[i])][k];
        if (w == static_cast<int>(v)) continue;
        auto it = std::find_if(first_with_other.begin(), first_with_other.end(),
                               [w](const std::pair<int, int>& e) { return e.first == w; });
        if (it == first_with_other.end())
          first_with_other.emplace_back(w, i);
        else
          fans_of.unite(i, it->second);
      }
    long fans = 0;
    for (int i = 0; i < size; ++i) fans += fans_of.find(i) == i;
    if (fans > 1) ++q.nonmanifold_vertices;
  }
  q.vertices = used;
}

}  // namespace

SurfaceComponents surface_components(const SurfaceMesh& mesh) {
  UnionFind<> uf(mesh.vertices.size());
  for (const auto& t : mesh.triangles) uf.unite(t[0], t[1]), uf.unite(t[1], t[2]);
  SurfaceComponents out;
  std::vector<int> label(mesh.vertices.size(), -1);
  for (const auto& t : mesh.triangles) {
    int& l = label[static_cast<size_t>(uf.find(t[0]))];
    if (l < 0) {
      l = static_cast<int>(out.enclosed_volume.size());
      out.enclosed_volume.push_back(0.0);
    }
    out.of_triangle.push_back(l);
    const auto& V = mesh.vertices;
    out.enclosed_volume[static_cast<size_t>(l)] +=
        V[static_cast<size_t>(t[0])].dot(V[static_cast<size_t>(t[1])].cross(V[static_cast<size_t>(t[2])])) / 6.0;
  }
  return out;
}

namespace {

// The distinct edges of `mesh`'s triangles: bucketed by their lower end,
// each there once per triangle side, counted once per bucket by marking
// the higher ends already met.
long distinct_edges(const SurfaceMesh& mesh) {
  const size_t n = mesh.vertices.size();
  std::vector<int> first(n + 1, 0), higher(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k)
      ++first[static_cast<size_t>(std::min(t[static_cast<size_t>(k)], t[static_cast<size_t>((k + 1) % 3)])) + 1];
  std::partial_sum(first.begin(), first.end(), first.begin());
  std::vector<int> fill(first.begin(), first.end() - 1);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = t[static_cast<size_t>(k)], b = t[static_cast<size_t>((k + 1) % 3)];
      higher[static_cast<size_t>(fill[static_cast<size_t>(std::min(a, b))]++)] = std::max(a, b);
    }
  long edges = 0;
  std::vector<int> seen_from(n, -1);  // the lower end whose bucket last held the vertex
  for (size_t v = 0; v < n; ++v)
    for (int k = first[v]; k < first[v + 1]; ++k) {
      const int b = higher[static_cast<size_t>(k)];
      if (seen_from[static_cast<size_t>(b)] == static_cast<int>(v)) continue;
      seen_from[static_cast<size_t>(b)] = static_cast<int>(v);
      ++edges;
    }
  return edges;
}

}  // namespace

SkinTopology mesh_topology(const SurfaceMesh& mesh) {
  // The edge count on another core, the components and their volumes
  // here: both only read the mesh.
  long edge_count = 0;
  tbb::task_group counting;
  counting.run([&] { edge_count = distinct_edges(mesh); });
  const SurfaceComponents components = surface_components(mesh);
  SkinTopology out;
  out.components = static_cast<long>(components.enclosed_volume.size());
  for (int c = 0; c < static_cast<int>(out.components); ++c) out.voids += components.is_cavity(c);
  std::vector<char> used(mesh.vertices.size(), 0);
  for (const auto& t : mesh.triangles)
    for (int v : t) used[static_cast<size_t>(v)] = 1;
  const long vertices = std::count(used.begin(), used.end(), 1);
  counting.wait();
  out.euler = vertices - edge_count + static_cast<long>(mesh.triangles.size());
  return out;
}

namespace {

// The solid angle of triangle abc seen from x, signed (Van Oosterom and
// Strackee 1983): summed over a closed surface it is 4 pi times the
// winding number of the surface about x.
double solid_angle(const Eigen::Vector3d& x, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d p = a - x, q = b - x, r = c - x;
  const double lp = p.norm(), lq = q.norm(), lr = r.norm();
  const double numerator = p.dot(q.cross(r));
  const double denominator = lp * lq * lr + p.dot(q) * lr + q.dot(r) * lp + r.dot(p) * lq;
  return 2 * std::atan2(numerator, denominator);
}

}  // namespace

std::vector<char> enclosed_components(const SurfaceMesh& mesh, const SurfaceComponents& components) {
  const size_t count = components.enclosed_volume.size();
  std::vector<int> witness(count, -1);  // one vertex per component
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    int& w = witness[static_cast<size_t>(components.of_triangle[f])];
    if (w < 0) w = mesh.triangles[f][0];
  }
  std::vector<char> enclosed(count, 0);
  tbb::parallel_for(size_t{0}, count, [&](size_t c) {
    const Eigen::Vector3d& x = mesh.vertices[static_cast<size_t>(witness[c])];
    std::vector<double> winding(count, 0.0);
    for (size_t f = 0; f < mesh.triangles.size(); ++f) {
      const size_t other = static_cast<size_t>(components.of_triangle[f]);
      if (other == c) continue;
      const std::array<int, 3>& t = mesh.triangles[f];
      winding[other] += solid_angle(x, mesh.vertices[static_cast<size_t>(t[0])], mesh.vertices[static_cast<size_t>(t[1])],
                                    mesh.vertices[static_cast<size_t>(t[2])]);
    }
    for (size_t other = 0; other < count; ++other)
      if (other != c && std::abs(winding[other]) > 2 * M_PI) enclosed[c] = 1;  // |winding number| 1, not 0
  });
  return enclosed;
}

SurfaceMesh outer_surface(const SurfaceMesh& mesh, std::vector<int>* kept_from) {
  const SurfaceComponents components = surface_components(mesh);
  const std::vector<char> enclosed = enclosed_components(mesh, components);
  std::vector<int> index(mesh.vertices.size(), -1);
  SurfaceMesh out;
  if (kept_from) kept_from->clear();
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (enclosed[static_cast<size_t>(components.of_triangle[f])]) continue;
    std::array<int, 3> t = mesh.triangles[f];
    for (int& v : t) {
      int& i = index[static_cast<size_t>(v)];
      if (i < 0) {
        i = static_cast<int>(out.vertices.size());
        out.vertices.push_back(mesh.vertices[static_cast<size_t>(v)]);
        if (mesh.normals.size() == mesh.vertices.size()) out.normals.push_back(mesh.normals[static_cast<size_t>(v)]);
        if (mesh.cells.size() == mesh.vertices.size()) out.cells.push_back(mesh.cells[static_cast<size_t>(v)]);
        if (kept_from) kept_from->push_back(v);
      }
      v = i;
    }
    out.triangles.push_back(t);
  }
  return out;
}

long GradeOptions::max_box_pairs(long triangles) const {
  const double bound = max_box_pairs_per_triangle * static_cast<double>(triangles);
  return bound >= 9e18 ? std::numeric_limits<long>::max() : std::max(kMinBoxPairs, static_cast<long>(bound));
}

MeshQuality grade_mesh(const SurfaceMesh& mesh, const GradeOptions& options) {
  MeshQuality q;
  // The parts write different fields of q and run side by side. The exact
  // self-intersection test, the longest, starts with them; its count is
  // used only if the mesh turns out manifold, oriented and without
  // degenerate triangles (given a degenerate one it returns at once).
  const bool exact = options.self_intersections == SelfIntersectionCheck::exact;
  SelfIntersectionCount crossing;
  SurfaceComponents components;
  tbb::parallel_invoke([&] { grade_triangles(mesh, q); }, [&] { grade_edges(mesh, q); },
                       [&] { grade_vertices(mesh, q); }, [&] { components = surface_components(mesh); },
                       [&] {
                         const long bound = options.max_box_pairs(static_cast<long>(mesh.triangles.size()));
                         if (exact)
                           crossing = options.changed ? check_changed_self_intersections(mesh, *options.changed, bound)
                                                      : check_self_intersections(mesh, bound);
                       });
  q.components = static_cast<long>(components.enclosed_volume.size());
  q.euler = q.vertices - q.edges + q.triangles;
  q.closed = q.boundary_edges == 0;
  q.manifold = q.nonmanifold_edges == 0 && q.nonmanifold_vertices == 0;
  q.oriented = q.inconsistent_edges == 0;
  if (q.closed && q.manifold && q.oriented) {
    q.genus = (2 * q.components - q.euler) / 2;
    // A closed component that encloses negative volume faces inward: with
    // outward normals everywhere else, it is the surface of a cavity.
    for (int c = 0; c < static_cast<int>(q.components); ++c) q.cavities += components.is_cavity(c);
  }
  if (exact && q.manifold && q.oriented && q.degenerate_triangles == 0) {
    q.self_intersections_checked = !crossing.degenerate && !crossing.over_bound;
    q.self_intersections_over_bound = crossing.over_bound;
    q.self_intersection_box_pairs = crossing.box_pairs;
    q.self_intersection_triangles_tested =
        options.changed ? std::count(options.changed->begin(), options.changed->end(), 1) : q.triangles;
    q.self_intersecting_pairs = q.self_intersections_checked ? crossing.pairs : 0;
  }
  return q;
}

}  // namespace skinmesh
