// Volume meshing by the TetGen program: the surface (and a box) written as a
// .smesh piecewise linear complex with facet markers, region points marking
// the interior, the solvent and cavities, hole points where nothing is to be
// meshed; `tetgen -pzAYQ -q<ratio>/<dihedral> [-a<volume>]` runs in a
// temporary directory and its .node/.ele/.face files are read back.
#include "skinmesh/meshing/volume_mesh.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/meshing/mesh_io.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <numeric>
#include <optional>
#include <sstream>
#include <unistd.h>

namespace skinmesh {
namespace {

constexpr double kTetgenTightening = 0.8;

// Triangles grouped into connected components (through shared vertices).
std::vector<int> triangle_components(const SurfaceMesh& mesh, int* count) {
  std::vector<int> parent(mesh.vertices.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[static_cast<size_t>(x)] != x) x = parent[static_cast<size_t>(x)] = parent[static_cast<size_t>(parent[static_cast<size_t>(x)])];
    return x;
  };
  for (const auto& t : mesh.triangles) {
    const int a = find(t[0]), b = find(t[1]), c = find(t[2]);
    parent[static_cast<size_t>(b)] = a;
    parent[static_cast<size_t>(find(c))] = a;
  }
  std::vector<int> label(mesh.vertices.size(), -1), out;
  *count = 0;
  for (const auto& t : mesh.triangles) {
    int& l = label[static_cast<size_t>(find(t[0]))];
    if (l < 0) l = (*count)++;
    out.push_back(l);
  }
  return out;
}

double signed_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  return a.dot(b.cross(c)) / 6.0;
}

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

std::string format_number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

struct Marked {
  Eigen::Vector3d point;
  int region;
};

// A TetGen .smesh: points, triangles with markers, hole points, region points.
void write_smesh(std::ostream& out, const std::vector<Eigen::Vector3d>& points,
                 const std::vector<std::array<int, 3>>& facets, const std::vector<int>& markers,
                 const std::vector<Eigen::Vector3d>& holes, const std::vector<Marked>& regions) {
  auto xyz = [](const Eigen::Vector3d& p) {
    return format_number(p[0]) + ' ' + format_number(p[1]) + ' ' + format_number(p[2]);
  };
  out << points.size() << " 3 0 0\n";
  for (size_t i = 0; i < points.size(); ++i) out << i << ' ' << xyz(points[i]) << '\n';
  out << facets.size() << " 1\n";
  for (size_t f = 0; f < facets.size(); ++f)
    out << "3 " << facets[f][0] << ' ' << facets[f][1] << ' ' << facets[f][2] << ' ' << markers[f] << '\n';
  out << holes.size() << '\n';
  for (size_t h = 0; h < holes.size(); ++h) out << h << ' ' << xyz(holes[h]) << '\n';
  out << regions.size() << '\n';
  for (size_t r = 0; r < regions.size(); ++r)
    out << r << ' ' << xyz(regions[r].point) << ' ' << regions[r].region << " -1\n";
}

std::string read_tail(const std::string& path) {
  std::ifstream in(path);
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return all.size() > 600 ? all.substr(all.size() - 600) : all;
}

struct TempDir {
  std::string path;
  TempDir() {
    char pattern[] = "/tmp/skinmesh-tetgen-XXXXXX";
    if (!mkdtemp(pattern)) throw VolumeMeshError("cannot create a temporary directory for TetGen");
    path = pattern;
  }
  ~TempDir() {
    for (const char* ext : {".smesh", ".1.node", ".1.ele", ".1.face", ".1.edge", ".1.smesh", ".log"})
      std::remove((path + "/plc" + ext).c_str());
    ::rmdir(path.c_str());
  }
};

}  // namespace

TetMesh tetrahedralize(const SurfaceMesh& surface_in, const VolumeOptions& options, TetImprovement* smoothing) {
  if (surface_in.triangles.empty()) throw VolumeMeshError("the surface has no triangles");
  if (!(options.max_radius_edge >= 1.0)) throw std::invalid_argument("the radius-edge bound must be at least 1");
  if (!(options.min_dihedral >= 0 && options.min_dihedral < 70))
    throw std::invalid_argument("the dihedral bound must be in [0, 70) degrees");
  if (!(options.max_volume >= 0)) throw std::invalid_argument("the volume bound must be >= 0");
  if (!(options.box_margin > 0)) throw std::invalid_argument("the box margin must be positive");

  // TetGen needs a closed surface: every edge in exactly two triangles, run
  // once each way (consistent orientation).
  {
    std::map<std::pair<int, int>, int> directed;
    for (const auto& t : surface_in.triangles)
      for (int k = 0; k < 3; ++k) ++directed[{t[static_cast<size_t>(k)], t[static_cast<size_t>((k + 1) % 3)]}];
    for (const auto& [edge, n] : directed) {
      const auto twin = directed.find({edge.second, edge.first});
      if (n != 1 || twin == directed.end() || twin->second != 1)
        throw VolumeMeshError("the surface is not a closed, consistently oriented manifold (edge " +
                              std::to_string(edge.first) + "-" + std::to_string(edge.second) + ")");
    }
  }

  // Components, their orientation (outer skin or cavity) and the dropping of
  // cavities (which fills them).
  int count = 0;
  std::vector<int> component = triangle_components(surface_in, &count);
  std::vector<double> volume(static_cast<size_t>(count), 0.0);
  for (size_t f = 0; f < surface_in.triangles.size(); ++f) {
    const auto& t = surface_in.triangles[f];
    volume[static_cast<size_t>(component[f])] += signed_volume(surface_in.vertices[static_cast<size_t>(t[0])],
                                                               surface_in.vertices[static_cast<size_t>(t[1])],
                                                               surface_in.vertices[static_cast<size_t>(t[2])]);
  }
  SurfaceMesh surface;
  surface.vertices = surface_in.vertices;
  std::vector<int> kept_component;
  for (size_t f = 0; f < surface_in.triangles.size(); ++f) {
    if (!options.keep_cavities && volume[static_cast<size_t>(component[f])] < 0) continue;
    surface.triangles.push_back(surface_in.triangles[f]);
    kept_component.push_back(component[f]);
  }
  component = kept_component;

  std::vector<Eigen::Vector3d> holes;
  std::vector<Marked> regions;
  std::vector<bool> seen(static_cast<size_t>(count), false);
  for (int c : component) seen[static_cast<size_t>(c)] = true;
  for (int c = 0; c < count; ++c) {
    if (!seen[static_cast<size_t>(c)]) continue;
    // Normals point out of the molecule: against them lies the interior
    // behind an outer skin, along them the void inside a cavity's surface.
    const bool cavity = volume[static_cast<size_t>(c)] < 0;
    const auto point = point_beside(surface, component, c, cavity ? 1.0 : -1.0);
    if (!point)
      throw VolumeMeshError("no point found " + std::string(cavity ? "inside the cavity" : "behind the skin") +
                            " of surface component " + std::to_string(c));
    if (!cavity) {
      if (options.domain == VolumeDomain::exterior) holes.push_back(*point);
      else regions.push_back({*point, kRegionInterior});
    } else {
      if (options.domain == VolumeDomain::interior) holes.push_back(*point);
      else regions.push_back({*point, kRegionCavity});
    }
  }

  // Vertices, then the box.
  std::vector<Eigen::Vector3d> points = surface.vertices;
  std::vector<std::array<int, 3>> facets = surface.triangles;
  std::vector<int> markers;
  for (int c : component) markers.push_back(volume[static_cast<size_t>(c)] < 0 ? kFaceCavity : kFaceSkin);
  if (options.domain != VolumeDomain::interior) {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
    for (const auto& t : surface.triangles)
      for (int v : t) {
        lo = lo.cwiseMin(surface.vertices[static_cast<size_t>(v)]);
        hi = hi.cwiseMax(surface.vertices[static_cast<size_t>(v)]);
      }
    lo -= Eigen::Vector3d::Constant(options.box_margin);
    hi += Eigen::Vector3d::Constant(options.box_margin);
    // Each side of the box as a grid of triangles about kBoxSpacing across:
    // TetGen may not split boundary facets (-Y), so two huge triangles a side
    // would leave slivers against them.
    constexpr double kBoxSpacing = 3.0;
    std::map<std::array<long long, 3>, int> box_index;  // grid coordinates -> point
    const Eigen::Vector3d extent = hi - lo;
    std::array<int, 3> cells{};
    for (int k = 0; k < 3; ++k) cells[static_cast<size_t>(k)] = std::max(1, static_cast<int>(std::ceil(extent[k] / kBoxSpacing)));
    auto box_point = [&](std::array<long long, 3> g) {
      auto [it, fresh] = box_index.try_emplace(g, static_cast<int>(points.size()));
      if (fresh) {
        Eigen::Vector3d p;
        for (int k = 0; k < 3; ++k)
          p[k] = g[static_cast<size_t>(k)] == cells[static_cast<size_t>(k)]
                     ? hi[k]
                     : lo[k] + extent[k] * static_cast<double>(g[static_cast<size_t>(k)]) / cells[static_cast<size_t>(k)];
        points.push_back(p);
      }
      return it->second;
    };
    for (int axis = 0; axis < 3; ++axis) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (int side = 0; side < 2; ++side) {
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
              facets.push_back({corner[0], corner[1], corner[2]});
              facets.push_back({corner[0], corner[2], corner[3]});
            } else {
              facets.push_back({corner[0], corner[2], corner[1]});
              facets.push_back({corner[0], corner[3], corner[2]});
            }
            markers.push_back(kFaceBox);
            markers.push_back(kFaceBox);
          }
      }
    }
    regions.push_back({lo + Eigen::Vector3d::Constant(0.5 * options.box_margin), kRegionSolvent});
  }

  TempDir dir;
  const std::string stem = dir.path + "/plc";
  {
    std::ofstream out(stem + ".smesh");
    write_smesh(out, points, facets, markers, holes, regions);
    if (!out) throw VolumeMeshError("cannot write TetGen's input in " + dir.path);
  }
  // -p: a piecewise linear complex; -z: zero-based; -A: region attributes;
  // -Y: no Steiner points on the surface; -Q: quiet; -q: quality bounds.
  // TetGen cannot split a tetrahedron whose refinement point would land on
  // the (unsplittable) surface, so a few next to it miss the bounds it is
  // given. It gets tighter ones, which leaves fewer such tetrahedra for
  // improve_tet_mesh (measured with 2.0/5 asked, 1ubi: TetGen at 2.0/5 left
  // 11, 1 of them beyond repair; at 1.6/10, none; at 1.2/10, 5, with twice
  // the tetrahedra of 1.6/10).
  std::ostringstream switches;
  // Below a ratio of about 1.2 or above about 18 degrees TetGen may not
  // terminate, so the tightened request stays inside those.
  switches << "-pzAYQ -q" << std::max(1.2, kTetgenTightening * options.max_radius_edge) << '/'
           << std::min(options.min_dihedral + 5.0, 18.0);
  if (options.max_volume > 0) switches << " -a" << options.max_volume;
  const std::string command =
      options.tetgen + ' ' + switches.str() + " '" + stem + ".smesh' > '" + stem + ".log' 2>&1";
  const int status = std::system(command.c_str());
  if (status != 0)
    throw VolumeMeshError("TetGen failed (" + command + "): " + read_tail(stem + ".log"));

  TetMesh mesh;
  try {
    mesh = read_tet_mesh(stem + ".1.ele");
  } catch (const InputError& e) {
    throw VolumeMeshError(std::string("TetGen's output: ") + e.what() + "; " + read_tail(stem + ".log"));
  }
  // TetGen orients tetrahedra its own way; make every one positive.
  for (auto& t : mesh.tets) {
    const Eigen::Vector3d& a = mesh.points[static_cast<size_t>(t[0])];
    if ((mesh.points[static_cast<size_t>(t[1])] - a).dot((mesh.points[static_cast<size_t>(t[2])] - a)
                                                            .cross(mesh.points[static_cast<size_t>(t[3])] - a)) < 0)
      std::swap(t[2], t[3]);
  }
  // The few tetrahedra TetGen leaves outside the bounds next to the surface.
  const TetImprovement improvement = improve_tet_mesh(mesh, options.max_radius_edge, options.min_dihedral);
  if (smoothing) *smoothing = improvement;
  return mesh;
}

long tetgen_self_intersections(const SurfaceMesh& surface, const std::string& tetgen) {
  TempDir dir;
  const std::string stem = dir.path + "/plc";
  {
    std::ofstream out(stem + ".smesh");
    write_smesh(out, surface.vertices, surface.triangles, std::vector<int>(surface.triangles.size(), kFaceSkin), {},
                {});
    if (!out) throw VolumeMeshError("cannot write TetGen's input in " + dir.path);
  }
  const std::string command = tetgen + " -dz '" + stem + ".smesh' > '" + stem + ".log' 2>&1";
  if (std::system(command.c_str()) != 0)
    throw VolumeMeshError("TetGen failed (" + command + "): " + read_tail(stem + ".log"));
  // TetGen says "!! Found N pairs of faces are intersecting." when it finds any.
  std::ifstream log(stem + ".log");
  std::string text;
  while (std::getline(log, text)) {
    const size_t at = text.find("Found ");
    if (at != std::string::npos && text.find("intersecting") != std::string::npos)
      return std::atol(text.c_str() + at + 6);
  }
  return 0;
}

}  // namespace skinmesh
