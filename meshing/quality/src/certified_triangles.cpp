// Certified triangles by sorted vectors: a frame's look-ups are binary
// searches, in parallel over its vertices and triangles.
#include "skinmesh/quality/certified_triangles.hpp"

#include "skinmesh/core/error.hpp"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>

namespace skinmesh {

namespace {

void check_sizes(const SurfaceMesh& mesh, const std::vector<long>& ids) {
  if (ids.size() != mesh.vertices.size()) contract_error("CertifiedTriangles: one id per vertex");
}

std::array<long, 3> corner_ids(const std::array<int, 3>& t, const std::vector<long>& ids) {
  std::array<long, 3> key{ids[static_cast<size_t>(t[0])], ids[static_cast<size_t>(t[1])], ids[static_cast<size_t>(t[2])]};
  std::sort(key.begin(), key.end());
  return key;
}

// Index sharing between two triangles is what the exact test reads besides
// the places (two triangles with a common corner may touch there), so ids
// must name vertices one to one in both frames for the certificate to carry.
bool distinct(std::vector<long> ids) {
  std::sort(ids.begin(), ids.end());
  return std::adjacent_find(ids.begin(), ids.end()) == ids.end();
}

}  // namespace

CertifiedTriangles::CertifiedTriangles(const SurfaceMesh& mesh, const std::vector<long>& ids) {
  check_sizes(mesh, ids);
  if (!distinct(ids)) return;
  places_.reserve(ids.size());
  for (size_t v = 0; v < ids.size(); ++v) {
    const Eigen::Vector3d& p = mesh.vertices[v];
    places_.push_back({ids[v], p.x(), p.y(), p.z()});
  }
  tbb::parallel_sort(places_.begin(), places_.end(), [](const Place& a, const Place& b) { return a.id < b.id; });
  triangles_.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) triangles_.push_back(corner_ids(t, ids));
  tbb::parallel_sort(triangles_.begin(), triangles_.end());
}

std::vector<char> CertifiedTriangles::changed(const SurfaceMesh& mesh, const std::vector<long>& ids) const {
  check_sizes(mesh, ids);
  std::vector<char> out(mesh.triangles.size(), 1);
  if (empty() || !distinct(ids)) return out;
  std::vector<char> still(ids.size(), 0);  // per vertex: its id certified, exactly where it was
  tbb::parallel_for(tbb::blocked_range<size_t>(0, ids.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) {
      const auto it = std::lower_bound(places_.begin(), places_.end(), ids[v],
                                       [](const Place& p, long id) { return p.id < id; });
      const Eigen::Vector3d& p = mesh.vertices[v];
      still[v] = it != places_.end() && it->id == ids[v] && it->x == p.x() && it->y == p.y() && it->z == p.z();
    }
  });
  tbb::parallel_for(tbb::blocked_range<size_t>(0, out.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t f = r.begin(); f != r.end(); ++f) {
      const auto& t = mesh.triangles[f];
      if (!still[static_cast<size_t>(t[0])] || !still[static_cast<size_t>(t[1])] || !still[static_cast<size_t>(t[2])])
        continue;
      out[f] = !std::binary_search(triangles_.begin(), triangles_.end(), corner_ids(t, ids));
    }
  });
  return out;
}

}  // namespace skinmesh
