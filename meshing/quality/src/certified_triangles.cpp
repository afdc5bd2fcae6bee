// Certified triangles as vertices sorted by id and triangles by their
// corners' ids: two frames are compared by merging, in one pass each.
#include "skinmesh/quality/certified_triangles.hpp"

#include "skinmesh/core/error.hpp"

#include <tbb/parallel_sort.h>

#include <algorithm>

namespace skinmesh {

CertifiedTriangles::CertifiedTriangles(const SurfaceMesh& mesh, const std::vector<long>& ids) {
  if (ids.size() != mesh.vertices.size()) contract_error("CertifiedTriangles: one id per vertex");
  vertex_count_ = mesh.vertices.size();
  mesh_triangles_ = mesh.triangles;
  places_.reserve(ids.size());
  for (size_t v = 0; v < ids.size(); ++v) {
    const Eigen::Vector3d& p = mesh.vertices[v];
    places_.push_back({ids[v], p.x(), p.y(), p.z(), static_cast<int>(v)});
  }
  tbb::parallel_sort(places_.begin(), places_.end(), [](const Place& a, const Place& b) { return a.id < b.id; });
  // Index sharing between two triangles is what the exact test reads besides
  // the places (two triangles with a common corner may touch there), so ids
  // must name vertices one to one for the certificate to carry.
  if (std::adjacent_find(places_.begin(), places_.end(), [](const Place& a, const Place& b) { return a.id == b.id; }) !=
      places_.end()) {
    places_.clear();
    return;
  }
  triangles_.reserve(mesh.triangles.size());
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    std::array<long, 3> key{ids[static_cast<size_t>(t[0])], ids[static_cast<size_t>(t[1])], ids[static_cast<size_t>(t[2])]};
    std::sort(key.begin(), key.end());
    triangles_.push_back({key, static_cast<int>(f)});
  }
  tbb::parallel_sort(triangles_.begin(), triangles_.end(),
                     [](const Corners& a, const Corners& b) { return a.ids < b.ids; });
}

std::vector<char> CertifiedTriangles::changed_in(const CertifiedTriangles& later) const {
  std::vector<char> out(later.mesh_triangles_.size(), 1);
  if (empty() || later.empty()) return out;
  std::vector<char> still(later.vertex_count_, 0);  // per vertex of `later`: here, at the same place
  auto here = places_.begin();
  for (const Place& p : later.places_) {
    while (here != places_.end() && here->id < p.id) ++here;
    still[static_cast<size_t>(p.vertex)] =
        here != places_.end() && here->id == p.id && here->x == p.x && here->y == p.y && here->z == p.z;
  }
  auto had = triangles_.begin();
  for (const Corners& c : later.triangles_) {
    while (had != triangles_.end() && had->ids < c.ids) ++had;
    if (had == triangles_.end() || had->ids != c.ids) continue;
    const auto& t = later.mesh_triangles_[static_cast<size_t>(c.triangle)];
    out[static_cast<size_t>(c.triangle)] =
        !(still[static_cast<size_t>(t[0])] && still[static_cast<size_t>(t[1])] && still[static_cast<size_t>(t[2])]);
  }
  return out;
}

}  // namespace skinmesh
