#include "births.hpp"

#include "judge.hpp"
#include "necks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>

namespace skinmesh::detail {
namespace {

// At most this many splits of the icosahedron (20 * 4^4 = 5,120
// triangles): the size criterion scales with a sphere's radius (its target
// edge is epsilon times the radius), the distance criterion does not, and a
// born sphere is small: one of radius 1.2 A passes the frames' criteria
// after two splits.
constexpr int kMostSplits = 4;

// A unit sphere's mesh: the icosahedron's 12 vertices and 20 faces,
// counter-clockwise seen from outside.
struct UnitSphere {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> triangles;
};

UnitSphere icosahedron() {
  const double g = (1 + std::sqrt(5.0)) / 2;
  UnitSphere m;
  for (const auto& p : std::initializer_list<std::array<double, 3>>{
           {-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
           {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}})
    m.points.push_back(Eigen::Vector3d(p[0], p[1], p[2]).normalized());
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  return m;
}

// Each triangle split in four at its edges' midpoints, put back on the sphere.
UnitSphere split(const UnitSphere& in) {
  UnitSphere out;
  out.points = in.points;
  std::map<std::pair<int, int>, int> midpoint;
  const auto middle = [&](int a, int b) {
    const auto key = std::minmax(a, b);
    const auto [it, made] = midpoint.try_emplace(key, static_cast<int>(out.points.size()));
    if (made) out.points.push_back((in.points[static_cast<size_t>(a)] + in.points[static_cast<size_t>(b)]).normalized());
    return it->second;
  };
  for (const auto& t : in.triangles) {
    const int ab = middle(t[0], t[1]), bc = middle(t[1], t[2]), ca = middle(t[2], t[0]);
    out.triangles.push_back({t[0], ab, ca});
    out.triangles.push_back({t[1], bc, ab});
    out.triangles.push_back({t[2], ca, bc});
    out.triangles.push_back({ab, bc, ca});
  }
  return out;
}

// `unit` placed on the sphere of `cell` (centre, radius) as the skin there:
// facing out for a component, in for a void. Empty when a vertex is
// outside the cell or a triangle fails the judge.
std::optional<SurfaceMesh> placed(const SkinComplex& complex, int cell, const Eigen::Vector3d& centre, double radius,
                                  bool is_void, const UnitSphere& unit, const MeshingOptions& criteria) {
  SurfaceMesh m;
  for (const Eigen::Vector3d& u : unit.points) {
    const Eigen::Vector3d x = centre + radius * u;
    if (complex.membership_violation(cell, x) > 0) return std::nullopt;
    m.vertices.push_back(x);
    m.cells.push_back(cell);
    m.normals.push_back(complex.gradient(cell, x).normalized());
  }
  for (std::array<int, 3> t : unit.triangles) {
    if (is_void) std::swap(t[1], t[2]);
    const std::array<Eigen::Vector3d, 3> corners{m.vertices[static_cast<size_t>(t[0])],
                                                 m.vertices[static_cast<size_t>(t[1])],
                                                 m.vertices[static_cast<size_t>(t[2])]};
    if (!triangle_passes(complex, corners, cell, criteria)) return std::nullopt;
    m.triangles.push_back(t);
  }
  return m;
}

// Whether a vertex of `mesh` lies in `cell` already: one that transport
// relocated onto the new skin there. The sphere is then not added (it
// would be meshed twice); the patch mends the birth with that vertex.
bool already_on(const SurfaceMesh& mesh, int cell) {
  return std::find(mesh.cells.begin(), mesh.cells.end(), cell) != mesh.cells.end();
}

}  // namespace

std::optional<SurfaceMesh> born_sphere(const SkinComplex& complex, const TopologyChange& change,
                                       const MeshingOptions& criteria) {
  if (!change.birth || (change.dim != 0 && change.dim != 3) || change.cell < 0 ||
      change.cell >= static_cast<int>(complex.cells().size()))
    return std::nullopt;
  const MixedCell& cell = complex.cell(change.cell);
  if (cell.degenerate || cell.dim != change.dim) return std::nullopt;
  // The cell's quadric with P = 0 (a vertex) or P = I (a tetrahedron).
  const double s = complex.shrink();
  const double radius2 = cell.dim == 0 ? -s * cell.R2 : (1 - s) * cell.R2;
  if (!(radius2 > 0)) return std::nullopt;
  const double radius = std::sqrt(radius2);
  UnitSphere unit = icosahedron();
  for (int splits = 1; splits <= kMostSplits; ++splits) {
    unit = split(unit);
    if (std::optional<SurfaceMesh> m = placed(complex, change.cell, cell.center, radius, cell.dim == 3, unit, criteria))
      return m;
  }
  return std::nullopt;
}

long add_born_spheres(const SkinComplex& complex, const SurfaceMesh& mesh, const std::vector<char>& failing,
                      const std::vector<TopologyChange>& changes, const MeshingOptions& criteria, RepairResult& r,
                      std::vector<char>& done) {
  done.resize(changes.size(), 0);
  long added = 0;
  for (size_t k = 0; k < changes.size(); ++k) {
    if (done[k] || !changes[k].birth || already_on(mesh, changes[k].cell)) continue;
    const std::optional<SurfaceMesh> sphere = born_sphere(complex, changes[k], criteria);
    if (!sphere) continue;
    if (!r.ok) {  // the frame as it was, every vertex its own origin
      r.ok = true;
      r.mesh = mesh;
      r.failing = failing;
      r.origin.resize(mesh.vertices.size());
      for (size_t v = 0; v < r.origin.size(); ++v) r.origin[v] = static_cast<long>(v);
      r.left = std::count(failing.begin(), failing.end(), 1);
    }
    // Cells and normals follow the vertices where the mesh keeps them.
    const size_t base = r.mesh.vertices.size();
    if (r.mesh.cells.size() == base) r.mesh.cells.insert(r.mesh.cells.end(), sphere->cells.begin(), sphere->cells.end());
    if (r.mesh.normals.size() == base)
      r.mesh.normals.insert(r.mesh.normals.end(), sphere->normals.begin(), sphere->normals.end());
    r.mesh.vertices.insert(r.mesh.vertices.end(), sphere->vertices.begin(), sphere->vertices.end());
    r.origin.resize(r.mesh.vertices.size(), -1);
    const int first = static_cast<int>(base);
    for (const auto& t : sphere->triangles) r.mesh.triangles.push_back({first + t[0], first + t[1], first + t[2]});
    r.failing.resize(r.mesh.triangles.size(), 0);
    done[k] = 1;
    ++added;
  }
  return added;
}

EventSurgery surgery_at_events(const SkinComplex& complex, const SurfaceMesh& mesh, const std::vector<char>& failing,
                               const MeshingOptions& criteria, const RepairPolicy& policy, LocalRepairOptions& local) {
  EventSurgery out;
  std::vector<char> done(local.changes.size(), 0);
  if (policy.neck_surgery) out.result = neck_surgery(complex, mesh, failing, local.changes, criteria, done);
  if (policy.birth_surgery) out.births = add_born_spheres(complex, mesh, failing, local.changes, criteria, out.result, done);
  out.necks = take_done_changes(done, local) - out.births;
  return out;
}

}  // namespace skinmesh::detail
