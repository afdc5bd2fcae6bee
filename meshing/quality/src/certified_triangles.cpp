// Certified triangles as a table of vertices by id and, per vertex, the
// triangles whose corner of least id it is: the next frame finds each of
// its triangles by a few reads, in parallel, with no sort.
#include "skinmesh/quality/certified_triangles.hpp"

#include "skinmesh/core/error.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>

namespace skinmesh {

namespace {

// MurmurHash3's 64-bit finaliser: ids that follow one another land in
// slots far apart.
size_t id_hash(long id) {
  uint64_t h = static_cast<uint64_t>(id);
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdULL;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53ULL;
  h ^= h >> 33;
  return static_cast<size_t>(h);
}

}  // namespace

CertifiedTriangles::CertifiedTriangles(const SurfaceMesh& mesh, const std::vector<long>& ids) {
  if (ids.size() != mesh.vertices.size()) contract_error("CertifiedTriangles: one id per vertex");
  mesh_triangles_ = mesh.triangles;  // the size of changed_in's answer, certified or not
  if (ids.empty()) return;
  ids_ = ids;
  // Index sharing between two triangles is what the exact test reads besides
  // the places (two triangles with a common corner may touch there), so ids
  // must name vertices one to one for the certificate to carry.
  if (!index_ids()) return;
  places_ = mesh.vertices;
  triangle_ids_.resize(mesh_triangles_.size());
  std::vector<int> lead(mesh_triangles_.size());  // per triangle: its corner of least id
  tbb::parallel_for(tbb::blocked_range<size_t>(0, mesh_triangles_.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t f = r.begin(); f != r.end(); ++f) {
      const auto& t = mesh_triangles_[f];
      std::array<long, 3>& key = triangle_ids_[f];
      key = {ids_[static_cast<size_t>(t[0])], ids_[static_cast<size_t>(t[1])], ids_[static_cast<size_t>(t[2])]};
      std::sort(key.begin(), key.end());
      lead[f] = vertex_with_id(key[0]);
    }
  });
  first_led_.assign(places_.size() + 1, 0);  // a counting sort by lead
  for (int v : lead) ++first_led_[static_cast<size_t>(v) + 1];
  for (size_t v = 1; v < first_led_.size(); ++v) first_led_[v] += first_led_[v - 1];
  led_.resize(lead.size());
  std::vector<int> fill(first_led_.begin(), first_led_.end() - 1);
  for (size_t f = 0; f < lead.size(); ++f) led_[static_cast<size_t>(fill[static_cast<size_t>(lead[f])]++)] = static_cast<int>(f);
  unique_ids_ = true;
}

bool CertifiedTriangles::index_ids() {
  const auto [low, high] = std::minmax_element(ids_.begin(), ids_.end());
  const double spread = static_cast<double>(*high) - static_cast<double>(*low) + 1;
  if (spread <= 8.0 * static_cast<double>(ids_.size()) + 4096) {
    first_id_ = *low;
    vertex_of_id_.assign(static_cast<size_t>(spread), -1);
    for (size_t v = 0; v < ids_.size(); ++v) {
      int& vertex = vertex_of_id_[static_cast<size_t>(ids_[v] - first_id_)];
      if (vertex >= 0) return false;
      vertex = static_cast<int>(v);
    }
    return true;
  }
  size_t size = 16;  // at most half full
  while (size < 2 * ids_.size()) size *= 2;
  id_slots_.assign(size, -1);
  for (size_t v = 0; v < ids_.size(); ++v) {
    size_t s = id_hash(ids_[v]) & (size - 1);
    for (; id_slots_[s] >= 0; s = (s + 1) & (size - 1))
      if (ids_[static_cast<size_t>(id_slots_[s])] == ids_[v]) return false;
    id_slots_[s] = static_cast<int>(v);
  }
  return true;
}

int CertifiedTriangles::vertex_with_id(long id) const {
  if (id_slots_.empty()) {
    const long k = id - first_id_;
    return k >= 0 && k < static_cast<long>(vertex_of_id_.size()) ? vertex_of_id_[static_cast<size_t>(k)] : -1;
  }
  for (size_t s = id_hash(id) & (id_slots_.size() - 1);; s = (s + 1) & (id_slots_.size() - 1)) {
    const int v = id_slots_[static_cast<size_t>(s)];
    if (v < 0 || ids_[static_cast<size_t>(v)] == id) return v;
  }
}

int CertifiedTriangles::triangle_with_ids(const std::array<long, 3>& ids) const {
  const int v = vertex_with_id(ids[0]);
  if (v < 0) return -1;
  for (int k = first_led_[static_cast<size_t>(v)]; k < first_led_[static_cast<size_t>(v) + 1]; ++k)
    if (triangle_ids_[static_cast<size_t>(led_[static_cast<size_t>(k)])] == ids) return led_[static_cast<size_t>(k)];
  return -1;
}

std::vector<char> CertifiedTriangles::changed_in(const CertifiedTriangles& later) const {
  std::vector<char> out(later.mesh_triangles_.size(), 1);
  if (empty() || later.empty()) return out;
  std::vector<char> still(later.places_.size(), 0);  // per vertex of `later`: here, at the same place
  tbb::parallel_for(tbb::blocked_range<size_t>(0, still.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) {
      const int here = vertex_with_id(later.ids_[v]);
      still[v] = here >= 0 && places_[static_cast<size_t>(here)] == later.places_[v];
    }
  });
  tbb::parallel_for(tbb::blocked_range<size_t>(0, out.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t f = r.begin(); f != r.end(); ++f) {
      const auto& t = later.mesh_triangles_[f];
      if (still[static_cast<size_t>(t[0])] && still[static_cast<size_t>(t[1])] && still[static_cast<size_t>(t[2])])
        out[f] = triangle_with_ids(later.triangle_ids_[f]) < 0;
    }
  });
  return out;
}

}  // namespace skinmesh
