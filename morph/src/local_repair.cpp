#include "local_repair.hpp"

#include "judge.hpp"
#include "mesh_part.hpp"

#include "skinmesh/core/cell_grid.hpp"
#include "skinmesh/core/union_find.hpp"
#include "skinmesh/core/vertex_stars.hpp"

#include <Eigen/Geometry>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <numeric>
#include <unordered_map>

namespace skinmesh::detail {
namespace {

using Triangle = std::array<int, 3>;
constexpr signed char kNone = -1;

// The failing triangles and every triangle within `rings` vertex-rings of them.
std::vector<char> grow_region(const SurfaceMesh& mesh, const VertexStars& stars, std::vector<char> region, int rings) {
  for (int r = 0; r < rings; ++r) {
    std::vector<char> next = region;
    for (size_t f = 0; f < region.size(); ++f)
      if (region[f])
        for (int v : mesh.triangles[f]) stars.each(v, [&](int g) { next[static_cast<size_t>(g)] = 1; });
    region.swap(next);
  }
  return region;
}

// The triangles marked in `region`, ascending.
std::vector<size_t> marked_triangles(const std::vector<char>& region) {
  std::vector<size_t> out;
  for (size_t f = 0; f < region.size(); ++f)
    if (region[f]) out.push_back(f);
  return out;
}

// Per vertex of a patch attempt: its PatchRole, or kNone; and the vertices
// with a role, so that the attempt's passes go over the patch and its
// context, not over the whole frame (`marked`, ascending once sorted).
struct Roles {
  std::vector<signed char> role;
  std::vector<int> marked;
  void mark(int v, PatchRole r) {
    signed char& at = role[static_cast<size_t>(v)];
    if (at == kNone) marked.push_back(v);
    at = static_cast<signed char>(r);
  }
  void sort() { std::sort(marked.begin(), marked.end()); }
};

// The roles of a patch on the triangles `in_region` (ascending). Two rings
// of context around the rim give the patch's Delaunay triangulation the
// neighbours its facets have in the whole frame.
Roles vertex_roles(const SurfaceMesh& mesh, const VertexStars& stars, const std::vector<char>& region,
                   const std::vector<size_t>& in_region) {
  Roles roles;
  roles.role.assign(mesh.vertices.size(), kNone);
  std::vector<signed char>& role = roles.role;
  for (size_t f : in_region)
    for (int v : mesh.triangles[f]) roles.mark(v, PatchRole::interior);
  roles.sort();
  std::vector<int> rim;
  for (int v : roles.marked) {
    bool whole = true;
    stars.each(v, [&](int f) { whole = whole && region[static_cast<size_t>(f)]; });
    if (!whole) {
      role[static_cast<size_t>(v)] = static_cast<signed char>(PatchRole::boundary);
      rim.push_back(v);
    }
  }
  for (int ring = 0; ring < 2; ++ring) {
    std::vector<int> next;
    for (int v : rim)
      stars.each(v, [&](int f) {
        for (int w : mesh.triangles[static_cast<size_t>(f)])
          if (role[static_cast<size_t>(w)] == kNone) {
            roles.mark(w, PatchRole::context);
            next.push_back(w);
          }
      });
    rim.swap(next);
  }
  return roles;
}

double longest_edge(const SurfaceMesh& mesh, const std::vector<size_t>& in_region) {
  double longest2 = 0;
  for (size_t f : in_region)
    for (size_t k = 0; k < 3; ++k) {
      const Eigen::Vector3d& a = mesh.vertices[static_cast<size_t>(mesh.triangles[f][k])];
      const Eigen::Vector3d& b = mesh.vertices[static_cast<size_t>(mesh.triangles[f][(k + 1) % 3])];
      longest2 = std::max(longest2, (a - b).squaredNorm());
    }
  return std::sqrt(longest2);
}

// Attempts a patch always gets (PatchPolicy::attempts permitting) before it
// may give up for want of progress.
constexpr int kAttemptsBeforeGivingUp = 4;

// `vertices` of the mesh in cubic cells over `box`, `cell` (Angstrom)
// wide or wider: at most four cells a vertex (and 64 more). Built for
// every attempt of a patch, from tens of thousands of vertices.
CellGrid grid_of_vertices(const SurfaceMesh& mesh, std::vector<int> vertices, const Eigen::AlignedBox3d& box,
                          double cell) {
  std::vector<Eigen::Vector3d> points(vertices.size());
  for (size_t k = 0; k < vertices.size(); ++k) points[k] = mesh.vertices[static_cast<size_t>(vertices[k])];
  CellGridOptions options;
  options.cell = cell;
  options.most_cells = 4.0 * static_cast<double>(vertices.size()) + 64;
  return CellGrid(std::move(points), std::move(vertices), box, options);
}

// Vertices near the patch that the mesh does not join to it (another sheet
// across a thin gap, the far side of a narrow neck) become context too.
// Without them the Voronoi edge of a patch facet runs on across the gap, its
// restricted point lies on the other sheet, and refinement meshes that sheet
// a second time: the repair fails (a wrong topology, or too many points)
// and the whole frame is remeshed. Near: within `times` `longest[v]` of
// patch vertex v (an edge length of the region's triangles, add_context;
// PatchPolicy::context_reach), about the diameter of a patch facet's
// surface Delaunay ball, and no farther than `cap` target lengths at v
// (infinite: no cap). `reach` gets that
// distance per vertex (0 off the patch). False, with `roles` part-marked,
// as soon as the patch and its context pass `most` vertices. `roles.marked`
// is ascending on entry; the context found is appended.
bool add_nearby_context(const SkinComplex& complex, const SurfaceMesh& mesh, const VertexStars& stars,
                        const std::vector<double>& longest, double times, const MeshingOptions& criteria, double cap,
                        size_t most, Roles& roles, std::vector<double>& reach) {
  const auto context = static_cast<signed char>(PatchRole::context);
  const std::vector<signed char>& role = roles.role;
  reach.assign(role.size(), 0.0);
  std::vector<double> reaches;
  std::vector<size_t> reaching;  // the patch vertices with a reach, ascending
  for (int u : roles.marked) {
    const auto v = static_cast<size_t>(u);
    if (role[v] == context || !(longest[v] > 0)) continue;
    reaching.push_back(v);
    reach[v] = times * longest[v];
    if (std::isfinite(cap))
      reach[v] = std::min(reach[v], cap * target_edge_length(complex, mesh.vertices[v], mesh.cells[v], criteria));
    reaches.push_back(reach[v]);
  }
  if (reaches.empty()) return true;
  // Only vertices in the patch's bounding box grown by the longest reach
  // can be near it: the grid holds those, not the whole frame.
  Eigen::AlignedBox3d near_box;
  double farthest = 0;
  for (size_t v : reaching)
    if (reach[v] > 0) {
      near_box.extend(mesh.vertices[v]);
      farthest = std::max(farthest, reach[v]);
    }
  near_box.min().array() -= farthest;
  near_box.max().array() += farthest;
  // A vertex no triangle uses (one an earlier part of the patch dropped) is no context.
  std::vector<int> outside;  // the patch
  for (int v = 0; v < static_cast<int>(mesh.vertices.size()); ++v)
    if (role[static_cast<size_t>(v)] == kNone && near_box.contains(mesh.vertices[static_cast<size_t>(v)]) &&
        !stars.empty(v))
      outside.push_back(v);
  // Grid cells half as wide as the median reach: most vertices search
  // 27-64 cells, about 3-8 times the volume of their ball.
  std::nth_element(reaches.begin(), reaches.begin() + static_cast<long>(reaches.size() / 2), reaches.end());
  const CellGrid grid = grid_of_vertices(mesh, std::move(outside), near_box, 0.5 * reaches[reaches.size() / 2]);
  // Marked at once, each vertex once: gathered in a list first, a vertex
  // came once for every patch vertex near it, and the list could outgrow
  // the rest of the morph.
  for (size_t v : reaching) {
    if (!(reach[v] > 0)) continue;
    const Eigen::Vector3d& p = mesh.vertices[v];
    const double reach2 = reach[v] * reach[v];
    grid.each_near(p, reach[v], [&](int w, const Eigen::Vector3d& q) {
      if ((q - p).squaredNorm() < reach2 && role[static_cast<size_t>(w)] == kNone) roles.mark(w, PatchRole::context);
    });
    if (roles.marked.size() > most) return false;
  }
  return true;
}

// Per vertex of the region's triangles, the longest edge of those
// triangles within `rings` rings of it (0 elsewhere).
std::vector<double> local_longest_edges(const SurfaceMesh& mesh, const std::vector<size_t>& in_region, int rings) {
  std::vector<double> longest(mesh.vertices.size(), 0.0);
  for (size_t f : in_region) {
    const Triangle& t = mesh.triangles[f];
    double edge = 0;
    for (size_t k = 0; k < 3; ++k)
      edge = std::max(edge, (mesh.vertices[static_cast<size_t>(t[k])] -
                             mesh.vertices[static_cast<size_t>(t[(k + 1) % 3])]).norm());
    for (int v : t) longest[static_cast<size_t>(v)] = std::max(longest[static_cast<size_t>(v)], edge);
  }
  // Each ring: every triangle's largest corner value, read before any is
  // raised, goes to its corners.
  std::vector<double> most(in_region.size());
  for (int r = 0; r < rings; ++r) {
    for (size_t i = 0; i < in_region.size(); ++i) {
      const Triangle& t = mesh.triangles[in_region[i]];
      most[i] = std::max({longest[static_cast<size_t>(t[0])], longest[static_cast<size_t>(t[1])],
                          longest[static_cast<size_t>(t[2])]});
    }
    for (size_t i = 0; i < in_region.size(); ++i)
      for (int v : mesh.triangles[in_region[i]])
        longest[static_cast<size_t>(v)] = std::max(longest[static_cast<size_t>(v)], most[i]);
  }
  return longest;
}

// The context of a patch (add_nearby_context), by one of two measures.
// Whole: the longest edge of the region's triangles, at every patch vertex.
// One triangle that transport stretched across a pinching neck is many
// target lengths long, and with it as the measure the context of a large
// patch took most of the frame (70-86% of the vertices of 3mht in
// bench_moving's DNA motion), each attempt then costing about a remesh of
// the whole frame. Past a quarter of the frame the reach is capped at six
// target lengths. A small patch keeps the uncapped reach: on small
// molecules the far context is what lets a stretched patch succeed. The
// measure is at least `at_least`: a patch meshed again in pieces keeps the
// reach of the whole. Local (`local_scale` > 0): at each patch vertex the
// longest region edge within two rings of it, times `local_scale`; the
// refinement is then held near the patch (mesh_patch's `within`: half the
// reach at each vertex), where this context covers the skin; the reach is
// at most `local_reach_cap` (PatchPolicy, > 0) times `local_scale` target
// lengths. `reach` gets the distance per vertex. Returns the largest measure.
// `roles.marked` is ascending on entry; the context is appended.
double add_context(const SkinComplex& complex, const SurfaceMesh& mesh, const VertexStars& stars,
                   const std::vector<size_t>& in_region, double at_least, double local_scale, double local_reach_cap,
                   double context_reach, const MeshingOptions& criteria, Roles& roles, std::vector<double>& reach) {
  constexpr double kLargeShare = 0.25;       // of the frame's vertices
  constexpr double kCapInTargetLengths = 6;  // dimensionless
  constexpr int kLocalRings = 2;
  std::vector<double> longest;
  double measure = 0;
  if (local_scale > 0) {
    // Only the corners of the region's triangles have an edge; all are marked.
    longest = local_longest_edges(mesh, in_region, kLocalRings);
    for (int v : roles.marked) {
      double& l = longest[static_cast<size_t>(v)];
      l *= local_scale;
      measure = std::max(measure, l);
    }
    for (int v : roles.marked)  // seeds on a newborn component have no edge yet
      if (!(longest[static_cast<size_t>(v)] > 0)) longest[static_cast<size_t>(v)] = measure;
  }
  if (!(measure > 0)) {
    // A region of seeds alone (a newborn component) takes the mesh's longest edge.
    measure = std::max(longest_edge(mesh, in_region), at_least);
    if (!(measure > 0)) {
      std::vector<size_t> all(mesh.triangles.size());
      std::iota(all.begin(), all.end(), size_t{0});
      measure = longest_edge(mesh, all);
    }
    longest.assign(mesh.vertices.size(), measure);
  }
  const size_t patch = roles.marked.size();
  const auto large = static_cast<size_t>(kLargeShare * static_cast<double>(roles.role.size()));
  // The local measure's cap grows with it (a stalled patch is tried again reaching farther).
  const double first_cap = local_scale > 0 && local_reach_cap > 0 ? local_scale * local_reach_cap
                                                                 : std::numeric_limits<double>::infinity();
  if (add_nearby_context(complex, mesh, stars, longest, context_reach, criteria, first_cap, large, roles, reach))
    return measure;
  // The first search stopped once it passed a quarter: its context is taken back.
  for (size_t k = patch; k < roles.marked.size(); ++k) roles.role[static_cast<size_t>(roles.marked[k])] = kNone;
  roles.marked.resize(patch);
  add_nearby_context(complex, mesh, stars, longest, context_reach, criteria, kCapInTargetLengths, SIZE_MAX, roles,
                     reach);
  return measure;
}

// Interior vertices crowded together along a patch edge: the later one goes.
std::vector<char> crowded_interior(const SkinComplex& complex, const SurfaceMesh& mesh,
                                   const std::vector<size_t>& in_region, const std::vector<signed char>& role,
                                   const MeshingOptions& criteria, double crowded_below) {
  std::vector<char> drop(mesh.vertices.size(), 0);
  auto interior = [&](int v) {
    return role[static_cast<size_t>(v)] == static_cast<signed char>(PatchRole::interior);
  };
  for (size_t f : in_region) {
    const Triangle& t = mesh.triangles[f];
    for (size_t k = 0; k < 3; ++k) {
      const int a = std::min(t[k], t[(k + 1) % 3]), b = std::max(t[k], t[(k + 1) % 3]);
      if (!interior(a) || !interior(b) || drop[static_cast<size_t>(a)] || drop[static_cast<size_t>(b)]) continue;
      const auto ua = static_cast<size_t>(a), ub = static_cast<size_t>(b);
      const double limit =
          crowded_below * std::min(target_edge_length(complex, mesh.vertices[ua], mesh.cells[ua], criteria),
                                   target_edge_length(complex, mesh.vertices[ub], mesh.cells[ub], criteria));
      if ((mesh.vertices[ua] - mesh.vertices[ub]).squaredNorm() < limit * limit) drop[ub] = 1;
    }
  }
  return drop;
}

// Whether the oriented triangles around v form one disk: the link edges
// (a -> b for each triangle (v, a, b)) make a single closed cycle.
bool star_is_disk(int v, const std::vector<Triangle>& around) {
  if (around.size() < 3) return false;
  std::unordered_map<int, int> next;
  for (const Triangle& t : around) {
    const size_t k = static_cast<size_t>(std::find(t.begin(), t.end(), v) - t.begin());
    if (!next.emplace(t[(k + 1) % 3], t[(k + 2) % 3]).second) return false;
  }
  const int start = next.begin()->first;
  int at = start;
  size_t steps = 0;
  do {
    const auto it = next.find(at);
    if (it == next.end()) return false;
    at = it->second;
    ++steps;
  } while (at != start && steps <= around.size());
  return at == start && steps == around.size();
}

// The vertices of the mesh around which the seam fails: a patch vertex
// whose triangles (kept ones plus the patch's) are not one disk, and the old
// corners of the patch triangles around a new point whose star is not a
// disk; such new points go to `open_new`. Empty when the seam holds. New
// points are numbered from mesh.vertices.size() on. Only the patch's own
// vertices (`marks`, ascending) and the new points can fail, so only their
// stars are gathered.
std::vector<int> seam_faults(const SurfaceMesh& mesh, const VertexStars& stars, const std::vector<char>& region,
                             const std::vector<Triangle>& fresh, const Roles& marks, const std::vector<char>& drop,
                             std::vector<int>& open_new) {
  const size_t old_vertices = mesh.vertices.size();
  const std::vector<signed char>& role = marks.role;
  auto own = [&](size_t v) {
    return role[v] == static_cast<signed char>(PatchRole::interior) ||
           role[v] == static_cast<signed char>(PatchRole::boundary);
  };
  std::vector<int> patch;  // the old vertices of the patch, ascending, then rows for the new points
  for (int v : marks.marked)
    if (own(static_cast<size_t>(v))) patch.push_back(v);
  size_t vertices = old_vertices;
  for (const Triangle& t : fresh)
    for (int v : t) vertices = std::max(vertices, static_cast<size_t>(v) + 1);
  const size_t rows = patch.size() + (vertices - old_vertices);
  // The row of vertex v: its place in `patch`, or after them for a new
  // point; -1 for an old vertex off the patch (context), whose star is not judged.
  const auto row_of = [&](int v) -> long {
    const auto u = static_cast<size_t>(v);
    if (u >= old_vertices) return static_cast<long>(patch.size() + (u - old_vertices));
    const auto it = std::lower_bound(patch.begin(), patch.end(), v);
    return it != patch.end() && *it == v ? it - patch.begin() : -1;
  };
  const auto vertex_of = [&](size_t row) {
    return row < patch.size() ? patch[row] : static_cast<int>(old_vertices + (row - patch.size()));
  };
  // The triangles around each row's vertex (the patch's, then the kept
  // ones), in compressed rows: `first[r]` to `first[r + 1]` in `around`.
  std::vector<int> first(rows + 1, 0);
  std::vector<std::array<long, 3>> rows_of(fresh.size());
  for (size_t f = 0; f < fresh.size(); ++f)
    for (size_t k = 0; k < 3; ++k) {
      rows_of[f][k] = row_of(fresh[f][k]);
      if (rows_of[f][k] >= 0) ++first[static_cast<size_t>(rows_of[f][k]) + 1];
    }
  for (size_t r = 0; r < patch.size(); ++r)
    stars.each(patch[r], [&](int f) { first[r + 1] += !region[static_cast<size_t>(f)]; });
  for (size_t r = 1; r <= rows; ++r) first[r] += first[r - 1];
  std::vector<Triangle> around(static_cast<size_t>(first.back()));
  std::vector<int> fill(first.begin(), first.end() - 1);
  for (size_t f = 0; f < fresh.size(); ++f)
    for (long r : rows_of[f])
      if (r >= 0) around[static_cast<size_t>(fill[static_cast<size_t>(r)]++)] = fresh[f];
  for (size_t r = 0; r < patch.size(); ++r)
    stars.each(patch[r], [&](int f) {
      if (!region[static_cast<size_t>(f)]) around[static_cast<size_t>(fill[r]++)] = mesh.triangles[static_cast<size_t>(f)];
    });
  std::vector<int> faults;
  std::vector<Triangle> star;
  for (size_t r = 0; r < rows; ++r) {
    const auto v = static_cast<size_t>(vertex_of(r));
    const auto from = around.begin() + first[r], to = around.begin() + first[r + 1];
    // an interior vertex may go; a rim vertex has kept triangles
    if (from == to) {
      if (v < old_vertices && role[v] == static_cast<signed char>(PatchRole::boundary) && !drop[v])
        faults.push_back(static_cast<int>(v));
      continue;
    }
    star.assign(from, to);
    if (star_is_disk(static_cast<int>(v), star)) continue;
    if (v < old_vertices) faults.push_back(static_cast<int>(v));
    else open_new.push_back(static_cast<int>(v));
    for (const Triangle& t : star)
      for (int w : t)
        if (static_cast<size_t>(w) < old_vertices) faults.push_back(w);
  }
  return faults;
}

// The components of a triangle mesh (vertices counted where a triangle uses them).
long component_count(const SurfaceMesh& mesh) {
  UnionFind<> sets(mesh.vertices.size());
  std::vector<char> used(mesh.vertices.size(), 0);
  for (const Triangle& t : mesh.triangles)
    for (int v : t) used[static_cast<size_t>(v)] = 1;
  long components = std::count(used.begin(), used.end(), 1);
  for (const Triangle& t : mesh.triangles)
    for (size_t k = 1; k < 3; ++k) components -= sets.unite(t[0], t[k]);
  return components;
}

// Drops the vertices no triangle uses and renumbers, in place (a frame's
// arrays are not copied again); origin maps each vertex back to the mesh
// before (or -1).
void compact(SurfaceMesh&& merged, size_t old_vertices, RepairResult& out) {
  std::vector<int> renumber(merged.vertices.size(), -1);
  for (const Triangle& t : merged.triangles)
    for (int v : t) renumber[static_cast<size_t>(v)] = 0;
  size_t kept = 0;
  out.origin.clear();
  for (size_t v = 0; v < renumber.size(); ++v) {
    if (renumber[v] < 0) continue;
    renumber[v] = static_cast<int>(kept);
    merged.vertices[kept] = merged.vertices[v];
    merged.cells[kept] = merged.cells[v];
    merged.normals[kept] = merged.normals[v];
    out.origin.push_back(v < old_vertices ? static_cast<int>(v) : -1);
    ++kept;
  }
  merged.vertices.resize(kept);
  merged.cells.resize(kept);
  merged.normals.resize(kept);
  for (Triangle& t : merged.triangles)
    for (int& v : t) v = renumber[static_cast<size_t>(v)];
  out.mesh = std::move(merged);
}

}  // namespace

namespace {

// The patch's vertices and context as samples for mesh_patch; `index`
// gets each sample's vertex in the mesh.
std::vector<SkinSample> patch_samples(const SurfaceMesh& mesh, const Roles& marks, const std::vector<char>& drop,
                                      std::vector<PatchRole>& roles, std::vector<int>& index) {
  const std::vector<signed char>& role = marks.role;
  std::vector<SkinSample> samples;
  for (int v : marks.marked) {  // ascending
    const auto u = static_cast<size_t>(v);
    if (drop[u]) continue;
    samples.push_back({mesh.vertices[u], mesh.cells[u]});
    roles.push_back(static_cast<PatchRole>(role[u]));
    index.push_back(v);
  }
  return samples;
}

// Whether the mesh has a triangle outside `region` on the corners of `t`
// (in any order): the patch meshed it again as the mesh has it.
bool kept_already(const SurfaceMesh& mesh, const VertexStars& stars, const std::vector<char>& region,
                  const Triangle& t) {
  Triangle key = t;
  std::sort(key.begin(), key.end());
  bool found = false;
  stars.each(t[0], [&](int f) {
    if (found || region[static_cast<size_t>(f)]) return;
    Triangle corners = mesh.triangles[static_cast<size_t>(f)];
    std::sort(corners.begin(), corners.end());
    found = corners == key;
  });
  return found;
}

// The patch's triangles in the mesh's numbering (new points after the
// mesh's vertices), without those the mesh keeps already.
std::vector<Triangle> patch_triangles(const SurfaceMesh& mesh, const VertexStars& stars,
                                      const std::vector<char>& region, const PatchMeshResult& patch,
                                      const std::vector<int>& index) {
  const long n = static_cast<long>(index.size());
  std::vector<Triangle> out;
  for (const auto& t : patch.triangles) {
    Triangle g;
    bool old_corners = true;
    for (size_t k = 0; k < 3; ++k) {
      old_corners = old_corners && t[k] < n;
      g[k] = t[k] < n ? index[static_cast<size_t>(t[k])]
                      : static_cast<int>(mesh.vertices.size() + static_cast<size_t>(t[k] - n));
    }
    if (!old_corners || !kept_already(mesh, stars, region, g)) out.push_back(g);
  }
  return out;
}

// Around the new points whose star is not a disk (seam_faults), the patch
// and context vertices within `reach` times the star's longest edge, added
// to `faults`: the missing triangles of such a star have a context corner
// (PatchPolicy::open_star_reach).
void add_near_open_stars(const SurfaceMesh& mesh, const Roles& marks,
                         const std::vector<SkinSample>& added, const std::vector<Triangle>& fresh,
                         const std::vector<int>& open_new, double reach, std::vector<int>& faults) {
  if (open_new.empty() || !(reach > 0)) return;
  const size_t n = mesh.vertices.size();
  auto at = [&](int v) -> const Eigen::Vector3d& {
    const auto u = static_cast<size_t>(v);
    return u < n ? mesh.vertices[u] : added[u - n].point;
  };
  std::unordered_map<int, double> longest;  // per open star's point
  for (int v : open_new) longest[v] = 0;
  for (const Triangle& t : fresh)
    for (size_t k = 0; k < 3; ++k) {
      const auto it = longest.find(t[k]);
      if (it == longest.end()) continue;
      it->second = std::max({it->second, (at(t[k]) - at(t[(k + 1) % 3])).norm(), (at(t[k]) - at(t[(k + 2) % 3])).norm()});
    }
  std::vector<int> near = marks.marked;  // the patch's and the context's vertices, ascending
  Eigen::AlignedBox3d box;
  for (int v : near) box.extend(mesh.vertices[static_cast<size_t>(v)]);
  double widest = 0;
  for (const auto& entry : longest) widest = std::max(widest, reach * entry.second);
  if (near.empty() || !(widest > 0)) return;
  const CellGrid grid = grid_of_vertices(mesh, std::move(near), box, widest);
  for (const auto& [v, edge] : longest) {
    const double r2 = reach * reach * edge * edge;
    const Eigen::Vector3d& p = at(v);
    grid.each_near(p, reach * edge, [&](int w, const Eigen::Vector3d& q) {
      if ((q - p).squaredNorm() < r2) faults.push_back(w);
    });
  }
}

// One attempt on `region`: the patch meshed, not yet in the mesh. Its new
// points are numbered from mesh.vertices.size() on. `faults` gets the
// vertices to grow the region around where the seam or a new triangle fails.
struct Attempt {
  std::string failed_because;  // empty when the patch meshed and has no faults
  std::vector<SkinSample> added;
  std::vector<Triangle> fresh;  // the patch's triangles, replacing the region's
  std::vector<int> faults;
  std::vector<int> open_new;    // new points (numbered as in `fresh`) whose star does not close
  std::vector<char> bad;        // per triangle of `fresh`: fails the frame criteria
  bool meshed = false;          // the refinement ended ok (faults may remain)
  bool stopped = false;         // the refinement stopped (stalled, over budget)
  bool too_large = false;       // not tried: with its context, nearly the whole frame
  long own = 0;                 // the patch's own points (its samples, less the context)
  long context = 0;             // its context vertices
  double reach_measure = 0;     // of its context (add_context), Angstrom
};

// Per triangle of `fresh`, 1 where it fails `accept`; corners from `mesh`
// or, numbered past it, from `added`.
std::vector<char> failing_fresh(const SkinComplex& complex, const SurfaceMesh& mesh,
                                const std::vector<SkinSample>& added, const std::vector<Triangle>& fresh,
                                const MeshingOptions& accept) {
  const size_t n = mesh.vertices.size();
  auto point = [&](int v) -> const SkinSample {
    const auto u = static_cast<size_t>(v);
    return u < n ? SkinSample{mesh.vertices[u], mesh.cells[u]} : added[u - n];
  };
  std::vector<char> bad(fresh.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, fresh.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t f = r.begin(); f != r.end(); ++f) {
      const SkinSample a = point(fresh[f][0]), b = point(fresh[f][1]), c = point(fresh[f][2]);
      bad[f] = !triangle_passes(complex, {a.point, b.point, c.point}, a.cell, accept);
    }
  });
  return bad;
}

// What earlier attempts of a patch leave to the next: the pieces they put
// in the mesh (their own points, the points they inserted) and the reach of
// the context (add_context). A patch meshed again in pieces keeps the
// budget (mesh_patch's: twice its own points plus 64, less what its pieces
// inserted) and the reach of the whole: a piece alone, with less context,
// can run away meshing the far side of a thin gap.
struct SoFar {
  long own = 0, inserted = 0;
  double reach_measure = 0;  // Angstrom
  double local_scale = 0;    // > 0: the context by the local measure, times this (add_context)
};

// `seeds`: the mesh's vertices in [first, second) that no triangle uses
// are seeds at topology changes (a newborn component, a neck), interior to
// the patch.
Attempt try_patch(const SkinComplex& complex, const SurfaceMesh& mesh, const VertexStars& stars,
                  const std::vector<char>& region, std::pair<size_t, size_t> seeds, const SoFar& so_far,
                  const MeshingOptions& repair, const MeshingOptions& accept, const LocalRepairOptions& options) {
  Attempt a;
  const std::vector<size_t> in_region = marked_triangles(region);
  Roles marks = vertex_roles(mesh, stars, region, in_region);
  for (size_t v = seeds.first; v < seeds.second; ++v)
    if (stars.empty(static_cast<int>(v))) marks.mark(static_cast<int>(v), PatchRole::interior);
  marks.sort();
  std::vector<double> reach;
  a.reach_measure = add_context(complex, mesh, stars, in_region, so_far.reach_measure, so_far.local_scale,
                                options.policy.local_reach_cap, options.policy.context_reach, accept, marks, reach);
  marks.sort();
  const std::vector<char> drop = crowded_interior(complex, mesh, in_region, marks.role, accept, options.crowded_below);
  std::vector<PatchRole> roles;
  std::vector<int> index;
  const std::vector<SkinSample> samples = patch_samples(mesh, marks, drop, roles, index);
  // Nearly the whole frame: no faults, so the caller remeshes it whole.
  if (static_cast<double>(samples.size()) > options.policy.max_sample_share * static_cast<double>(mesh.vertices.size())) {
    a.failed_because = "the patch took nearly the whole frame (" + std::to_string(samples.size()) + " of " +
                       std::to_string(mesh.vertices.size()) + " vertices)";
    a.too_large = true;
    return a;
  }
  a.own = std::count_if(roles.begin(), roles.end(), [](PatchRole r) { return r != PatchRole::context; });
  a.context = static_cast<long>(samples.size()) - a.own;
  const long budget = 2 * (so_far.own + a.own) + 64 - so_far.inserted;
  std::vector<double> within;  // a local context holds the refinement within half its reach
  if (so_far.local_scale > 0)
    for (int v : index) within.push_back(0.5 * reach[static_cast<size_t>(v)]);
  PatchMeshResult patch = mesh_patch(complex, samples, roles, repair, budget, within);
  if (patch.status != MeshingStatus::ok) {  // no faults: growing would not help
    a.stopped = true;
    a.failed_because = std::string("the patch's refinement ended ") + meshing_status_name(patch.status) + " (" +
                       patch.message + ")";
    return a;
  }
  a.meshed = true;
  a.fresh = patch_triangles(mesh, stars, region, patch, index);
  a.added = std::move(patch.added);
  a.faults = seam_faults(mesh, stars, region, a.fresh, marks, drop, a.open_new);
  add_near_open_stars(mesh, marks, a.added, a.fresh, a.open_new, options.policy.open_star_reach, a.faults);
  const size_t seam = a.faults.size();
  a.bad = failing_fresh(complex, mesh, a.added, a.fresh, accept);
  const std::vector<char>& bad = a.bad;
  for (size_t f = 0; f < a.fresh.size(); ++f)
    if (bad[f])
      for (int v : a.fresh[f])
        if (static_cast<size_t>(v) < mesh.vertices.size()) a.faults.push_back(v);
  if (!a.faults.empty())
    a.failed_because = std::to_string(seam) + " seam faults and " +
                       std::to_string(std::count(bad.begin(), bad.end(), 1)) +
                       " new triangles failing the frame criteria left after growing the patch";
  return a;
}

// The parts of an attempt that hold: pieces of the region joined with the
// patch triangles that replace them (vertices shared by region or patch
// triangles make one piece) and holding no fault. Such a piece is stitched
// with disk stars all round and every new triangle passing, whatever the
// other pieces do: kept triangles separate it from them.
struct Holding {
  std::vector<char> region;  // per triangle of the mesh: in the region and in a piece that holds
  std::vector<char> fresh;   // per triangle of the attempt: in a piece that holds
  long pieces = 0, faulty = 0;
  long own = 0;  // vertices of the region's triangles in pieces that hold
};

Holding holding_pieces(const SurfaceMesh& mesh, const std::vector<char>& region, const Attempt& a) {
  const size_t n = mesh.vertices.size();
  UnionFind<> pieces(n + a.added.size());
  const auto join = [&](const Triangle& t) {
    for (size_t k = 1; k < 3; ++k) pieces.unite(t[k], t[0]);
  };
  for (size_t f = 0; f < region.size(); ++f)
    if (region[f]) join(mesh.triangles[f]);
  for (const Triangle& t : a.fresh) join(t);
  std::vector<char> faulty(pieces.size(), 0);
  for (int v : a.faults) faulty[static_cast<size_t>(pieces.find(v))] = 1;
  Holding h;
  h.region.assign(region.size(), 0);
  std::vector<char> seen(pieces.size(), 0);
  for (size_t f = 0; f < region.size(); ++f) {
    if (!region[f]) continue;
    const size_t root = static_cast<size_t>(pieces.find(mesh.triangles[f][0]));
    h.region[f] = !faulty[root];
    if (!seen[root]) {
      seen[root] = 1;
      ++h.pieces;
      h.faulty += faulty[root];
    }
  }
  std::vector<char> own(n, 0);
  for (size_t f = 0; f < region.size(); ++f)
    if (h.region[f])
      for (int v : mesh.triangles[f]) own[static_cast<size_t>(v)] = 1;
  h.own = std::count(own.begin(), own.end(), 1);
  h.fresh.resize(a.fresh.size());
  for (size_t f = 0; f < a.fresh.size(); ++f) h.fresh[f] = !faulty[static_cast<size_t>(pieces.find(a.fresh[f][0]))];
  return h;
}

// The whole of attempt `a` as if it held: every region triangle replaced
// by every patch triangle (Retry::around_faults).
Holding everything(const SurfaceMesh& mesh, const std::vector<char>& region, const Attempt& a) {
  Holding h;
  h.region = region;
  h.fresh.assign(a.fresh.size(), 1);
  h.pieces = 1;
  std::vector<char> own(mesh.vertices.size(), 0);
  for (size_t f = 0; f < region.size(); ++f)
    if (region[f])
      for (int v : mesh.triangles[f]) own[static_cast<size_t>(v)] = 1;
  h.own = std::count(own.begin(), own.end(), 1);
  return h;
}

// The vertices marked in `touched` whose triangles are there but do not
// make one disk.
std::vector<int> open_stars(const SurfaceMesh& mesh, const VertexStars& stars, const std::vector<char>& touched) {
  std::vector<int> open;
  std::vector<Triangle> around;
  for (int v = 0; v < static_cast<int>(touched.size()); ++v) {
    if (!touched[static_cast<size_t>(v)] || stars.empty(v)) continue;
    around.clear();
    stars.each(v, [&](int f) { around.push_back(mesh.triangles[static_cast<size_t>(f)]); });
    if (!star_is_disk(v, around)) open.push_back(v);
  }
  return open;
}

// open_stars without a VertexStars of the whole mesh: the triangles around
// the touched vertices alone, gathered in one pass over the triangles.
std::vector<int> open_stars(const SurfaceMesh& mesh, const std::vector<char>& touched) {
  std::vector<int> marked;  // ascending
  for (size_t v = 0; v < touched.size(); ++v)
    if (touched[v]) marked.push_back(static_cast<int>(v));
  if (marked.empty()) return {};
  std::vector<int> row(touched.size(), -1);
  for (size_t r = 0; r < marked.size(); ++r) row[static_cast<size_t>(marked[r])] = static_cast<int>(r);
  const auto row_of = [&](int v) { return static_cast<size_t>(row[static_cast<size_t>(v)]); };
  const auto is_touched = [&](int v) { return static_cast<size_t>(v) < touched.size() && touched[static_cast<size_t>(v)]; };
  std::vector<int> first(marked.size() + 1, 0);
  for (const Triangle& t : mesh.triangles)
    for (int v : t)
      if (is_touched(v)) ++first[row_of(v) + 1];
  for (size_t r = 1; r < first.size(); ++r) first[r] += first[r - 1];
  std::vector<Triangle> around(static_cast<size_t>(first.back()));
  std::vector<int> fill(first.begin(), first.end() - 1);
  for (const Triangle& t : mesh.triangles)
    for (int v : t)
      if (is_touched(v)) around[static_cast<size_t>(fill[row_of(v)]++)] = t;
  std::vector<int> open;
  std::vector<Triangle> star;
  for (size_t r = 0; r < marked.size(); ++r) {
    if (first[r] == first[r + 1]) continue;
    star.assign(around.begin() + first[r], around.begin() + first[r + 1]);
    if (!star_is_disk(marked[r], star)) open.push_back(marked[r]);
  }
  return open;
}

// The pieces of `a` that hold put into `mesh` (new points appended, in the
// order the patch made them); `region` follows the mesh's triangles (the
// region's triangles not replaced, none of the new ones). Returns the
// points added; `placed` gets each new point's vertex in the mesh (-1: not
// put in).
long put_in(const SkinComplex& complex, SurfaceMesh& mesh, std::vector<char>& region, const Attempt& a,
            const Holding& h, std::vector<int>& placed) {
  const size_t n = mesh.vertices.size();
  std::vector<Triangle> triangles;
  std::vector<char> still;
  triangles.reserve(mesh.triangles.size() + a.fresh.size());
  for (size_t f = 0; f < mesh.triangles.size(); ++f)
    if (!h.region[f]) {
      triangles.push_back(mesh.triangles[f]);
      still.push_back(region[f]);
    }
  placed.assign(a.added.size(), -1);
  for (size_t f = 0; f < a.fresh.size(); ++f) {
    if (!h.fresh[f]) continue;
    Triangle t = a.fresh[f];
    for (int& v : t) {
      if (static_cast<size_t>(v) < n) continue;
      int& at = placed[static_cast<size_t>(v) - n];
      if (at < 0) {
        const SkinSample& p = a.added[static_cast<size_t>(v) - n];
        at = static_cast<int>(mesh.vertices.size());
        mesh.vertices.push_back(p.point);
        mesh.cells.push_back(p.cell);
        mesh.normals.push_back(complex.evaluate(p.point, p.cell).gradient.normalized());
      }
      v = at;
    }
    triangles.push_back(t);
    still.push_back(0);
  }
  mesh.triangles = std::move(triangles);
  region = std::move(still);
  return static_cast<long>(mesh.vertices.size() - n);
}

}  // namespace

namespace {

// Skin points projected from `change`'s apex (with_apex) and from six
// points along the axes `offset` away from it, from its cell.
std::vector<SkinSample> skin_points_around(const SkinComplex& complex, const TopologyChange& change, double offset,
                                           bool with_apex) {
  std::vector<SkinSample> out;
  for (int k = with_apex ? -1 : 0; k < 6; ++k) {
    Eigen::Vector3d from = change.point;
    if (k >= 0) from[k / 2] += (k % 2 ? -1 : 1) * offset;
    const Projection p = complex.project(from, change.cell, 1e-14);
    if (p.converged) out.push_back({p.point, p.cell});
  }
  return out;
}

// Adds `points` to `into` but those within 1e-6 A of one already added
// after its first `own` entries.
void add_distinct(const std::vector<SkinSample>& points, size_t own, std::vector<SkinSample>& into) {
  for (const SkinSample& p : points) {
    const bool known = std::any_of(into.begin() + static_cast<long>(own), into.end(),
                                   [&](const SkinSample& q) { return (q.point - p.point).norm() < 1e-6; });
    if (!known) into.push_back(p);
  }
}

// Skin points around each change: from six points half its size (at least
// 1e-3 A) away along the axes, and from its apex unless it is a birth and
// `apex_of_births` is false (a birth's apex is the new sphere's centre, and
// the six points inside the new sphere lead out to it). Points within
// 1e-6 A of another are left out.
std::vector<SkinSample> points_at_changes(const SkinComplex& complex, const std::vector<TopologyChange>& changes,
                                          bool apex_of_births) {
  std::vector<SkinSample> seeds;
  for (const TopologyChange& c : changes)
    add_distinct(skin_points_around(complex, c, std::max(0.5 * c.size, 1e-3), apex_of_births || !c.birth), 0, seeds);
  return seeds;
}

// The mesh with skin points around every topology change added as vertices
// no triangle uses yet: a component or void born in the step has no vertex
// on it, and a neck that opened can be too thin for any (events.hpp); from
// these the patch meshes them.
SurfaceMesh with_seeds_at_changes(const SkinComplex& complex, const SurfaceMesh& mesh,
                                  const std::vector<TopologyChange>& changes) {
  const std::vector<SkinSample> seeds = points_at_changes(complex, changes, false);
  // Room for the seeds and the patch's new points (put_in) before the copy:
  // appending to an exact copy of a frame's arrays would copy them again.
  const size_t room = seeds.size() + std::max<size_t>(4096, mesh.vertices.size() / 16);
  SurfaceMesh seeded;
  seeded.vertices.reserve(mesh.vertices.size() + room);
  seeded.cells.reserve(mesh.cells.size() + room);
  seeded.normals.reserve(mesh.normals.size() + room);
  seeded.vertices = mesh.vertices;
  seeded.cells = mesh.cells;
  seeded.normals = mesh.normals;
  seeded.triangles = mesh.triangles;
  for (const SkinSample& p : seeds) {
    seeded.vertices.push_back(p.point);
    seeded.cells.push_back(p.cell);
    seeded.normals.push_back(complex.evaluate(p.point, p.cell).gradient.normalized());
  }
  return seeded;
}

// The triangles with a corner near a topology change (each vertex
// tested once, in parallel: a frame has up to dozens of changes).
void mark_near_changes(const SurfaceMesh& mesh, const std::vector<TopologyChange>& changes,
                       std::vector<char>& region) {
  if (changes.empty()) return;
  std::vector<char> near(mesh.vertices.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, near.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v)
      near[v] = std::any_of(changes.begin(), changes.end(), [&](const TopologyChange& c) {
        return (mesh.vertices[v] - c.point).squaredNorm() <= c.radius * c.radius;
      });
  });
  for (size_t f = 0; f < mesh.triangles.size(); ++f)
    for (int v : mesh.triangles[f])
      if (near[static_cast<size_t>(v)]) region[f] = 1;
}

// V - E + F of a closed triangle mesh (every edge in two triangles, so
// E = 3F/2), vertices counted where a triangle uses them.
long closed_euler(const SurfaceMesh& mesh) {
  std::vector<char> used(mesh.vertices.size(), 0);
  for (const Triangle& t : mesh.triangles)
    for (int v : t) used[static_cast<size_t>(v)] = 1;
  const long faces = static_cast<long>(mesh.triangles.size());
  return std::count(used.begin(), used.end(), 1) - 3 * faces / 2 + faces;
}

// The Euler characteristic must change by what the critical events say
// (Morse theory, exact: events.hpp; none without a change), so a patch
// that grew a second layer or closed a piece off shows up here; the
// components may change by no more than one a change (none without). When
// the caller certifies the components after the patch, they are not
// counted here.
bool topology_as_expected(const SurfaceMesh& before, const SurfaceMesh& after, const LocalRepairOptions& options) {
  if (closed_euler(after) != closed_euler(before) + options.euler_change) return false;
  if (options.components_certified_after) return true;
  const long components_before = component_count(before);
  const long components_after = component_count(after);
  return std::abs(components_after - components_before) <= static_cast<long>(options.changes.size());
}

// How an attempt after the first meshes the patch: only the pieces that did
// not hold (the others go into the mesh at once), the whole region again,
// or only around the first attempt's faults (every triangle of it goes
// into the mesh at once, and the next region is the triangles, old or
// new, around the vertices where the seam or a new triangle failed; then
// on in pieces).
enum class Retry { pieces, whole, around_faults };

// How the attempts on a patch in pieces ended, when they failed.
struct PiecesFailure {
  bool put_in = false;       // some attempt put pieces in the mesh
  bool ran_away = false;     // the last attempt's refinement stopped (stalled, over budget)
  bool too_large = false;    // the patch with its context took nearly the whole frame
};

// Marks the corners of the region's triangles, whose stars a put-in of the
// whole attempt changes.
void mark_touched(const SurfaceMesh& mesh, const std::vector<char>& region, std::vector<char>& touched) {
  touched.resize(mesh.vertices.size(), 0);
  for (size_t f = 0; f < region.size(); ++f)
    if (region[f])
      for (int v : mesh.triangles[f]) touched[static_cast<size_t>(v)] = 1;
}

// After the whole of attempt `a` went into `mesh` (its new points from
// `before` on, as `placed` says), the faults to mesh around next: the
// attempt's own (old vertices keep their numbers), its new points whose
// star did not close, the new corners of its failing triangles, and every
// touched vertex whose star is not one disk now. The new points join
// `touched`.
void faults_after_all_in(const SurfaceMesh& mesh, const VertexStars& stars, const Attempt& a, size_t before,
                         const std::vector<int>& placed, std::vector<char>& touched, std::vector<int>& faults) {
  auto in_mesh = [&](int v) {
    return static_cast<size_t>(v) < before ? v : placed[static_cast<size_t>(v) - before];
  };
  for (int v : a.open_new) faults.push_back(in_mesh(v));
  for (size_t f = 0; f < a.fresh.size(); ++f)
    if (a.bad[f])
      for (int v : a.fresh[f]) faults.push_back(in_mesh(v));
  touched.resize(mesh.vertices.size(), 0);
  for (int v : placed)
    if (v >= 0) touched[static_cast<size_t>(v)] = 1;
  for (int v : open_stars(mesh, stars, touched)) faults.push_back(v);
  faults.erase(std::remove(faults.begin(), faults.end(), -1), faults.end());
}

// The attempts on one patch.
RepairResult patch_attempts(const SkinComplex& complex, const SurfaceMesh& given, const std::vector<char>& failing,
                            const MeshingOptions& repair, const MeshingOptions& accept,
                            const LocalRepairOptions& options, Retry retry, double local_scale,
                            PiecesFailure& failure) {
  RepairResult out;
  // The frame as the patch's pieces go into it, with seeds at the topology changes.
  SurfaceMesh mesh = with_seeds_at_changes(complex, given, options.changes);
  const std::pair<size_t, size_t> seeds{given.vertices.size(), mesh.vertices.size()};
  auto stars = std::make_unique<VertexStars>(mesh);
  std::vector<char> region = failing;
  mark_near_changes(mesh, options.changes, region);
  region = grow_region(mesh, *stars, std::move(region), options.policy.rings);
  size_t fewest = SIZE_MAX;  // the fewest faults an attempt left
  int since_fewest = 0;
  SoFar so_far;
  so_far.local_scale = local_scale;
  bool widened = false;
  std::vector<char> touched;  // vertices whose star an all-in put-in changed (Retry::around_faults)
  for (int attempt = 0; attempt < options.policy.attempts; ++attempt) {
    ++out.attempts;
    out.attempted_triangles += std::count(region.begin(), region.end(), 1);
    const Attempt a = try_patch(complex, mesh, *stars, region, seeds, so_far, repair, accept, options);
    out.context_vertices += a.context;
    so_far.reach_measure = std::max(so_far.reach_measure, a.reach_measure);
    // A refinement that stalls is most often meshing the far side of a thin
    // gap its context missed: the same region once more, reaching farther.
    if (a.stopped && !widened && options.policy.stalled_reach_scale > 1) {
      widened = true;
      if (so_far.local_scale > 0)
        so_far.local_scale *= options.policy.stalled_reach_scale;
      else
        so_far.reach_measure = options.policy.stalled_reach_scale * a.reach_measure;
      out.failed_because = a.failed_because;  // should this have been the last attempt
      failure.ran_away = true;
      continue;
    }
    failure.ran_away = false;
    if (!a.meshed) {  // no faults: growing would not help
      out.failed_because = a.failed_because;
      failure.ran_away = a.stopped;
      failure.too_large = a.too_large;
      return out;
    }
    // The pieces that hold go in now (all of them when there are no
    // faults); the next attempt remeshes the others, grown around their faults.
    const bool all_in = retry == Retry::around_faults && attempt == 0 && !a.faults.empty();
    const Holding holding = all_in ? everything(mesh, region, a) : holding_pieces(mesh, region, a);
    const bool put = a.faults.empty() || all_in || (retry != Retry::whole && holding.faulty < holding.pieces);
    std::vector<int> faults = a.faults;  // in the mesh's numbering after the put-in
    if (put) {
      out.counts.patch_triangles += std::count(holding.region.begin(), holding.region.end(), 1);
      const size_t before = mesh.vertices.size();
      if (all_in) mark_touched(mesh, region, touched);
      std::vector<int> placed;
      const long inserted = put_in(complex, mesh, region, a, holding, placed);
      out.counts.insertions += inserted;
      so_far.own += holding.own;
      so_far.inserted += inserted;
      if (!a.faults.empty()) {
        failure.put_in = true;
        stars = std::make_unique<VertexStars>(mesh);
      }
      if (all_in) faults_after_all_in(mesh, *stars, a, before, placed, touched, faults);
    }
    if (a.faults.empty()) {
      if (!open_stars(mesh, touched).empty()) {
        out.failed_because = "a vertex the patch's attempts touched has triangles that are not one disk";
        return out;
      }
      if (!topology_as_expected(given, mesh, options)) {
        out.failed_because = "the patched mesh's Euler characteristic or components are not what the topology "
                             "changes say";
        out.wrong_topology = true;
        return out;
      }
      compact(std::move(mesh), given.vertices.size(), out);
      out.ok = true;
      out.failed_because.clear();  // an earlier attempt's
      return out;
    }
    out.failed_because = a.failed_because;
    // Growing the patch around its faults leaves a fraction of them when
    // it is going to succeed, at times more for an attempt or two. Past the
    // first kAttemptsBeforeGivingUp, two attempts in a row that left no
    // fewer faults than the fewest before end it.
    if (a.faults.size() < fewest) {
      fewest = a.faults.size();
      since_fewest = 0;
    } else if (++since_fewest >= 2 && attempt + 1 >= kAttemptsBeforeGivingUp) {
      return out;
    }
    std::vector<char> more(region.size(), 0);
    for (int v : faults) stars->each(v, [&](int f) { more[static_cast<size_t>(f)] = 1; });
    more = grow_region(mesh, *stars, std::move(more), 1);
    bool grew = false;
    for (size_t f = 0; f < region.size(); ++f)
      if (more[f] && !region[f]) region[f] = grew = true;
    // The same region would be meshed the same way again.
    if (!grew) return out;
  }
  return out;
}

// The attempt counts of `earlier` added to `later`'s.
void add_attempts(const RepairResult& earlier, RepairResult& later) {
  later.attempts += earlier.attempts;
  later.context_vertices += earlier.context_vertices;
  later.attempted_triangles += earlier.attempted_triangles;
}

Retry piecewise(const PatchPolicy& policy) { return policy.retry_around_faults ? Retry::around_faults : Retry::pieces; }

// Retrying only the pieces that did not hold is cheaper, but a piece alone
// can fail where the whole region succeeds: its refinement runs away with
// less of the patch around it. Then the whole region is tried as well. (A
// patch in pieces that ends with faults or the wrong Euler characteristic
// ended the same way whole on bench_moving's 3mht motions.)
RepairResult whole_context_patch(const SkinComplex& complex, const SurfaceMesh& given, const std::vector<char>& failing,
                                 const MeshingOptions& repair, const MeshingOptions& accept,
                                 const LocalRepairOptions& options) {
  PiecesFailure failure;
  if (!options.policy.retry_in_pieces)
    return patch_attempts(complex, given, failing, repair, accept, options, Retry::whole, 0, failure);
  RepairResult out = patch_attempts(complex, given, failing, repair, accept, options, piecewise(options.policy), 0,
                                    failure);
  if (out.ok || !failure.put_in || !failure.ran_away) return out;
  RepairResult whole = patch_attempts(complex, given, failing, repair, accept, options, Retry::whole, 0, failure);
  add_attempts(out, whole);
  return whole;
}

}  // namespace

std::vector<SkinSample> seeds_at_changes(const SkinComplex& complex, const std::vector<TopologyChange>& changes) {
  return points_at_changes(complex, changes, true);
}

namespace {

// A local context first (PatchPolicy::local_context_first); when that
// fails, the whole region's measure, unless the local patch already took
// nearly the whole frame (a larger context would too: `too_large`).
RepairResult patch_with_contexts(const SkinComplex& complex, const SurfaceMesh& given,
                                 const std::vector<char>& failing, const MeshingOptions& repair,
                                 const MeshingOptions& accept, const LocalRepairOptions& options, bool& too_large) {
  too_large = false;
  if (!options.policy.local_context_first) return whole_context_patch(complex, given, failing, repair, accept, options);
  PiecesFailure failure;
  const Retry retry = options.policy.retry_in_pieces ? piecewise(options.policy) : Retry::whole;
  RepairResult local = patch_attempts(complex, given, failing, repair, accept, options, retry, 1.0, failure);
  too_large = failure.too_large;
  if (local.ok || failure.too_large) return local;
  RepairResult whole = whole_context_patch(complex, given, failing, repair, accept, options);
  add_attempts(local, whole);
  return whole;
}

}  // namespace

// The patch with its contexts; when it fails, once more with
// PatchPolicy::wider_rings more rings, unless its seam held and the
// topology did not.
RepairResult repair_locally(const SkinComplex& complex, const SurfaceMesh& given, const std::vector<char>& failing,
                           const MeshingOptions& repair, const MeshingOptions& accept,
                           const LocalRepairOptions& options) {
  bool too_large = false;
  RepairResult first = patch_with_contexts(complex, given, failing, repair, accept, options, too_large);
  if (first.ok || too_large || first.wrong_topology || options.policy.wider_rings <= 0) return first;
  LocalRepairOptions wider = options;
  wider.policy.rings += options.policy.wider_rings;
  RepairResult again = patch_with_contexts(complex, given, failing, repair, accept, wider, too_large);
  add_attempts(first, again);
  if (!again.ok)
    again.failed_because = first.failed_because + "; with " + std::to_string(wider.policy.rings) +
                           " rings: " + again.failed_because;
  return again;
}

}  // namespace skinmesh::detail
