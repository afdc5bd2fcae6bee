// Volume meshing by TetGen's library (Debian's libtet1.5-dev), in memory:
// the surface (and a box) handed over as a piecewise linear complex with
// facet markers, region points marking the interior, the solvent and
// cavities, hole points where nothing is to be meshed; TetGen runs with
// `pzAYQ q<ratio>/<dihedral> [a<volume>]` and its tetrahedra, regions and
// marked boundary faces are read from its output structure, in a child
// process (tetgen_run.hpp says why). No shell, no temporary files; TetGen's
// errors and crashes become statuses with a message.
#include "skinmesh/volume/volume_mesh.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/quality/mesh_quality.hpp"
#include "skinmesh/quality/tet_quality.hpp"
#include "skinmesh/volume/tet_estimate.hpp"

#include "tetgen_run.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <optional>
#include <sstream>
#include <vector>

namespace skinmesh {
namespace {

using detail::Plc;

constexpr double kTetgenTightening = 0.8;

// Whether the open segment p-q meets a triangle of the mesh (Moller-Trumbore).
bool segment_hits_mesh(const SurfaceMesh& mesh, const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  const Eigen::Vector3d d = q - p;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[static_cast<size_t>(t[0])];
    const Eigen::Vector3d e1 = mesh.vertices[static_cast<size_t>(t[1])] - a, e2 = mesh.vertices[static_cast<size_t>(t[2])] - a;
    const Eigen::Vector3d h = d.cross(e2);
    const double det = e1.dot(h);
    if (std::abs(det) < 1e-300) continue;
    const Eigen::Vector3d s = p - a;
    const double u = s.dot(h) / det;
    if (u < 0 || u > 1) continue;
    const Eigen::Vector3d qq = s.cross(e1);
    const double v = d.dot(qq) / det;
    if (v < 0 || u + v > 1) continue;
    const double w = e2.dot(qq) / det;
    if (w > 1e-12 && w < 1) return true;
  }
  return false;
}

// A point strictly on one side of component c: off the centroid of one of its
// triangles along the normal (side = +1 outward, -1 inward), a small fraction
// of that triangle's size, checked not to cross any other triangle.
std::optional<Eigen::Vector3d> point_beside(const SurfaceMesh& mesh, const std::vector<int>& component, int c,
                                            double side) {
  std::vector<int> order;
  for (int f = 0; f < static_cast<int>(mesh.triangles.size()); ++f)
    if (component[static_cast<size_t>(f)] == c) order.push_back(f);
  // Try the largest triangles first: they sit where the surface is flattest.
  auto area = [&](int f) {
    const auto& t = mesh.triangles[static_cast<size_t>(f)];
    const Eigen::Vector3d& a = mesh.vertices[static_cast<size_t>(t[0])];
    return (mesh.vertices[static_cast<size_t>(t[1])] - a).cross(mesh.vertices[static_cast<size_t>(t[2])] - a).norm();
  };
  std::sort(order.begin(), order.end(), [&](int x, int y) { return area(x) > area(y); });
  if (order.size() > 8) order.resize(8);
  for (int f : order) {
    const auto& t = mesh.triangles[static_cast<size_t>(f)];
    const Eigen::Vector3d& a = mesh.vertices[static_cast<size_t>(t[0])];
    const Eigen::Vector3d& b = mesh.vertices[static_cast<size_t>(t[1])];
    const Eigen::Vector3d& cc = mesh.vertices[static_cast<size_t>(t[2])];
    const Eigen::Vector3d n = (b - a).cross(cc - a).normalized();
    const Eigen::Vector3d g = (a + b + cc) / 3.0;
    const double shortest = std::min({(b - a).norm(), (cc - b).norm(), (a - cc).norm()});
    const Eigen::Vector3d p = g + side * 0.2 * shortest * n;
    // From the centroid the segment leaves through this triangle only.
    if (!segment_hits_mesh(mesh, g + side * 1e-9 * shortest * n, p)) return p;
  }
  return std::nullopt;
}

void check_options(const VolumeOptions& options) {
  if (!(options.bounds.max_radius_edge >= 1.0)) contract_error("the radius-edge bound must be at least 1");
  if (!(options.bounds.min_dihedral >= 0 && options.bounds.min_dihedral < 70))
    contract_error("the dihedral bound must be in [0, 70) degrees");
  if (!(options.max_volume >= 0)) contract_error("the volume bound must be >= 0");
  if (!(options.box_margin > 0)) contract_error("the box margin must be positive");
  if (!(options.max_tetrahedra > 0)) contract_error("the tetrahedron budget must be positive");
}

// The outer box: the bounding box of the triangles' corners grown by the
// margin on every side (Angstrom).
struct Box {
  Eigen::Vector3d lo, hi;
};
Box box_around(const std::vector<Eigen::Vector3d>& points, const std::vector<std::array<int, 3>>& triangles,
               double margin) {
  Box b{Eigen::Vector3d::Constant(INFINITY), Eigen::Vector3d::Constant(-INFINITY)};
  for (const auto& t : triangles)
    for (int v : t) {
      b.lo = b.lo.cwiseMin(points[static_cast<size_t>(v)]);
      b.hi = b.hi.cwiseMax(points[static_cast<size_t>(v)]);
    }
  b.lo -= Eigen::Vector3d::Constant(margin);
  b.hi += Eigen::Vector3d::Constant(margin);
  return b;
}

// The surface's triangles (less the filled cavities) with their markers, and a
// region or hole point for every component kept. Returns a message when a
// component has no point beside it.
std::string add_surface(const SurfaceMesh& surface_in, const VolumeOptions& options, Plc& plc) {
  const SurfaceComponents components = surface_components(surface_in);
  SurfaceMesh surface;
  surface.vertices = surface_in.vertices;
  std::vector<int> component;
  for (size_t f = 0; f < surface_in.triangles.size(); ++f) {
    const int c = components.of_triangle[f];
    if (options.cavities == Cavities::fill && components.is_cavity(c)) continue;
    surface.triangles.push_back(surface_in.triangles[f]);
    component.push_back(c);
  }
  std::vector<bool> seen(components.enclosed_volume.size(), false);
  for (int c : component) seen[static_cast<size_t>(c)] = true;
  for (int c = 0; c < static_cast<int>(seen.size()); ++c) {
    if (!seen[static_cast<size_t>(c)]) continue;
    // Normals point out of the molecule: against them lies the interior
    // behind an outer skin, along them the void inside a cavity's surface.
    const bool cavity = components.is_cavity(c);
    const auto point = point_beside(surface, component, c, cavity ? 1.0 : -1.0);
    if (!point)
      return "no point found " + std::string(cavity ? "inside the cavity" : "behind the skin") +
             " of surface component " + std::to_string(c);
    const bool hole = cavity ? options.domain == VolumeDomain::interior : options.domain == VolumeDomain::exterior;
    if (hole) plc.holes.push_back(*point);
    else plc.regions.push_back({*point, cavity ? kRegionCavity : kRegionInterior});
  }
  plc.points = surface.vertices;
  plc.facets = surface.triangles;
  for (int c : component) plc.markers.push_back(components.is_cavity(c) ? kFaceCavity : kFaceSkin);
  return "";
}

// The outer box `margin` beyond the surface's bounding box, each side a grid
// of triangles about kBoxSpacing across, and the solvent's region point.
void add_box(double margin, Plc& plc) {
  const Box box = box_around(plc.points, plc.facets, margin);
  const Eigen::Vector3d lo = box.lo, hi = box.hi;  // named, not bound: lambdas below capture them
  const Eigen::Vector3d extent = hi - lo;
  std::array<int, 3> cells{};
  for (int k = 0; k < 3; ++k) cells[static_cast<size_t>(k)] = std::max(1, static_cast<int>(std::ceil(extent[k] / kBoxSpacing)));
  std::map<std::array<long long, 3>, int> box_index;  // grid coordinates -> point
  auto box_point = [&](std::array<long long, 3> g) {
    auto [it, fresh] = box_index.try_emplace(g, static_cast<int>(plc.points.size()));
    if (fresh) {
      Eigen::Vector3d p;
      for (int k = 0; k < 3; ++k)
        p[k] = g[static_cast<size_t>(k)] == cells[static_cast<size_t>(k)]
                   ? hi[k]
                   : lo[k] + extent[k] * static_cast<double>(g[static_cast<size_t>(k)]) / cells[static_cast<size_t>(k)];
      plc.points.push_back(p);
    }
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side)
      for (int i = 0; i < cells[static_cast<size_t>(u)]; ++i)
        for (int j = 0; j < cells[static_cast<size_t>(v)]; ++j) {
          int corner[4];
          const int du[4] = {0, 1, 1, 0}, dv[4] = {0, 0, 1, 1};
          for (int k = 0; k < 4; ++k) {
            std::array<long long, 3> g{};
            g[static_cast<size_t>(axis)] = side ? cells[static_cast<size_t>(axis)] : 0;
            g[static_cast<size_t>(u)] = i + du[k];
            g[static_cast<size_t>(v)] = j + dv[k];
            corner[k] = box_point(g);
          }
          // (u, v, axis) is right-handed: the quad runs counter-clockwise seen
          // from +axis, which is outward on the far side.
          if (side) {
            plc.facets.push_back({corner[0], corner[1], corner[2]});
            plc.facets.push_back({corner[0], corner[2], corner[3]});
          } else {
            plc.facets.push_back({corner[0], corner[2], corner[1]});
            plc.facets.push_back({corner[0], corner[3], corner[2]});
          }
          plc.markers.push_back(kFaceBox);
          plc.markers.push_back(kFaceBox);
        }
  }
  plc.regions.push_back({lo + Eigen::Vector3d::Constant(0.5 * margin), kRegionSolvent});
}

VolumeMeshResult failed(VolumeStatus status, std::string message) {
  VolumeMeshResult r;
  r.status = status;
  r.message = std::move(message);
  return r;
}

// What keeps a surface from bounding a volume.
std::string not_closed(const MeshQuality& q) {
  return "the surface is not a closed, consistently oriented manifold (" + std::to_string(q.boundary_edges) +
         " boundary, " + std::to_string(q.nonmanifold_edges) + " non-manifold and " +
         std::to_string(q.inconsistent_edges) + " inconsistently oriented edges, " +
         std::to_string(q.nonmanifold_vertices) + " non-manifold vertices)";
}

// TetGen's switches: -p a piecewise linear complex; -z zero-based; -A region
// attributes; -Y no Steiner points on the surface; -Q quiet; -q quality bounds.
// TetGen cannot split a tetrahedron whose refinement point would land on the
// (unsplittable) surface, so a few next to it miss the bounds it is given. It
// gets tighter ones, which leaves fewer such tetrahedra for improve_tet_mesh
// (much tighter ones leave more again, among many more tetrahedra).
// Below a ratio of about 1.2 or above about 18 degrees TetGen may not
// terminate, so the tightened request stays inside those.
std::string tetgen_switches(const VolumeOptions& options) {
  std::ostringstream switches;
  switches << "pzAYQq" << tetgen_ratio(options.bounds) << '/' << tetgen_dihedral(options.bounds);
  if (options.max_volume > 0) switches << 'a' << options.max_volume;
  return switches.str();
}

// Runs TetGen on the complex and takes its tetrahedra, every one
// positively oriented.
VolumeMeshResult run_tetgen(const Plc& plc, const VolumeOptions& options) {
  detail::TetgenRun run =
      detail::run_tetgen(plc, tetgen_switches(options), {options.max_memory_bytes, options.max_seconds});
  if (!run.error.empty())
    return failed(VolumeStatus::tetgen_failed, run.error + " (switches " + tetgen_switches(options) + ")");
  VolumeMeshResult result;
  result.mesh = std::move(run.mesh);
  const auto& p = result.mesh.points;
  for (auto& t : result.mesh.tets)
    if (signed_tet_volume(p[static_cast<size_t>(t[0])], p[static_cast<size_t>(t[1])], p[static_cast<size_t>(t[2])],
                          p[static_cast<size_t>(t[3])]) < 0)
      std::swap(t[2], t[3]);
  return result;
}

}  // namespace

double tetgen_ratio(const TetBounds& bounds) { return std::max(1.2, kTetgenTightening * bounds.max_radius_edge); }
double tetgen_dihedral(const TetBounds& bounds) { return std::min(bounds.min_dihedral + 5.0, 18.0); }

const char* volume_status_name(VolumeStatus status) {
  switch (status) {
    case VolumeStatus::ok: return "ok";
    case VolumeStatus::surface_not_closed: return "surface_not_closed";
    case VolumeStatus::tetgen_failed: return "tetgen_failed";
    case VolumeStatus::over_budget: return "over_budget";
  }
  return "unknown";
}

VolumeMeshResult tetrahedralize(const SurfaceMesh& surface, const VolumeOptions& options) {
  check_options(options);
  if (surface.triangles.empty()) return failed(VolumeStatus::surface_not_closed, "the surface has no triangles");
  // TetGen needs a closed surface: every edge in exactly two triangles, run
  // once each way (consistent orientation).
  GradeOptions topology_only;
  topology_only.self_intersections = SelfIntersectionCheck::skip;
  const MeshQuality q = grade_mesh(surface, topology_only);
  if (!(q.closed && q.manifold && q.oriented)) return failed(VolumeStatus::surface_not_closed, not_closed(q));
  const TetDomain domain = tet_domain(surface, q.volume);
  const std::string too_many = tet_budget_refusal(domain, options);
  if (!too_many.empty()) return failed(VolumeStatus::over_budget, too_many);
  const TetEstimate estimate = estimate_tetrahedra(domain, options);
  Plc plc;
  const std::string missing = add_surface(surface, options, plc);
  if (!missing.empty()) return failed(VolumeStatus::surface_not_closed, missing);
  if (options.domain != VolumeDomain::interior) add_box(options.box_margin, plc);
  const auto started = std::chrono::steady_clock::now();
  VolumeMeshResult result = run_tetgen(plc, options);
  result.estimated_tetrahedra = estimate.tetrahedra;
  result.estimated_low = estimate.low;
  // TetGen's commonest input error, named (checked only when it failed).
  if (result.status == VolumeStatus::tetgen_failed) {
    const long crossing = count_self_intersections(surface);
    if (crossing > 0)
      result.message += "; the surface intersects itself (" + std::to_string(crossing) + " triangle pairs, CGAL exact)";
  }
  // The few tetrahedra TetGen leaves outside the bounds next to the surface.
  if (result.status != VolumeStatus::ok) return result;
  double left = 0;  // of the time bound, after TetGen
  if (options.max_seconds > 0) {
    left = options.max_seconds - std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    if (left <= 0) left = 1e-9;
  }
  result.improvement = improve_tet_mesh(result.mesh, options.bounds, left);
  if (result.improvement.timed_out)
    return failed(VolumeStatus::tetgen_failed,
                  "the clean-up of TetGen's tetrahedra ran past the time allowed (" +
                      std::to_string(static_cast<long>(std::ceil(options.max_seconds))) + " s, --max-seconds) with " +
                      std::to_string(result.improvement.bad_after) + " tetrahedra still outside the bounds");
  return result;
}

long tetgen_self_intersections(const SurfaceMesh& surface) {
  Plc plc;
  plc.points = surface.vertices;
  plc.facets = surface.triangles;
  plc.markers.assign(surface.triangles.size(), kFaceSkin);
  // -d: TetGen's intersection detection; it hands back the faces that meet
  // another one as its boundary faces.
  const detail::TetgenRun run = detail::run_tetgen(plc, "dzQ");
  return run.error.empty() ? static_cast<long>(run.mesh.faces.size()) : -1;
}

}  // namespace skinmesh
