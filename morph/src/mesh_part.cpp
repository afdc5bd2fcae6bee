#include "mesh_part.hpp"

#include <Eigen/Geometry>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace skinmesh::detail {

SurfaceMesh used_part(const SurfaceMesh& mesh, const std::vector<char>& keep_triangle, std::vector<int>& kept_from) {
  auto kept = [&](size_t f) { return keep_triangle.empty() || keep_triangle[f]; };
  std::vector<int> renumber(mesh.vertices.size(), -1);
  for (size_t f = 0; f < mesh.triangles.size(); ++f)
    if (kept(f))
      for (int v : mesh.triangles[f]) renumber[static_cast<size_t>(v)] = 0;
  SurfaceMesh part;
  kept_from.clear();
  const size_t vertices = static_cast<size_t>(std::count(renumber.begin(), renumber.end(), 0));
  part.vertices.reserve(vertices);
  part.cells.reserve(vertices);
  part.normals.reserve(vertices);
  kept_from.reserve(vertices);
  part.triangles.reserve(keep_triangle.empty() ? mesh.triangles.size()
                                               : static_cast<size_t>(std::count_if(keep_triangle.begin(), keep_triangle.end(),
                                                                               [](char k) { return k != 0; })));
  for (size_t v = 0; v < renumber.size(); ++v) {
    if (renumber[v] < 0) continue;
    renumber[v] = static_cast<int>(part.vertices.size());
    part.vertices.push_back(mesh.vertices[v]);
    part.cells.push_back(mesh.cells[v]);
    part.normals.push_back(mesh.normals[v]);
    kept_from.push_back(static_cast<int>(v));
  }
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (!kept(f)) continue;
    const auto& t = mesh.triangles[f];
    part.triangles.push_back({renumber[static_cast<size_t>(t[0])], renumber[static_cast<size_t>(t[1])],
                              renumber[static_cast<size_t>(t[2])]});
  }
  return part;
}

}  // namespace skinmesh::detail

namespace skinmesh::detail {

long mark_crowded(const SkinComplex& complex, const SurfaceMesh& mesh, const MeshingOptions& criteria, double below,
                  std::vector<char>& drop) {
  std::vector<double> target(mesh.vertices.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, target.size(), 512), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v)
      target[v] = target_edge_length(complex, mesh.vertices[v], mesh.cells[v], criteria);
  });
  long marked = 0;
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      size_t a = static_cast<size_t>(t[static_cast<size_t>(k)]), b = static_cast<size_t>(t[static_cast<size_t>((k + 1) % 3)]);
      if (a > b) std::swap(a, b);
      if (drop[a] || drop[b]) continue;
      const double limit = below * std::min(target[a], target[b]);
      if ((mesh.vertices[a] - mesh.vertices[b]).squaredNorm() < limit * limit) {
        drop[b] = 1;
        ++marked;
      }
    }
  return marked;
}

double density_over_fresh(const SkinComplex& complex, const SurfaceMesh& mesh, const MeshingOptions& criteria) {
  if (mesh.triangles.empty()) return 0;
  std::vector<double> target(mesh.vertices.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, target.size(), 512), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v)
      target[v] = target_edge_length(complex, mesh.vertices[v], mesh.cells[v], criteria);
  });
  double fresh = 0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[static_cast<size_t>(t[0])];
    const Eigen::Vector3d& b = mesh.vertices[static_cast<size_t>(t[1])];
    const Eigen::Vector3d& c = mesh.vertices[static_cast<size_t>(t[2])];
    const double length = std::min({target[static_cast<size_t>(t[0])], target[static_cast<size_t>(t[1])],
                                    target[static_cast<size_t>(t[2])]});
    fresh += 0.5 * (b - a).cross(c - a).norm() / (std::sqrt(3.0) / 4 * length * length);
  }
  return static_cast<double>(mesh.triangles.size()) / std::max(fresh, 1.0);
}

RepairResult remesh_from_vertices(const SkinComplex& complex, const SurfaceMesh& mesh, const std::vector<char>& drop,
                                  const MeshingOptions& criteria, const std::vector<SkinSample>& seeds) {
  std::vector<SkinSample> samples;
  std::vector<long> sample_vertex;  // per sample: its vertex in `mesh`, -1 for a seed
  samples.reserve(mesh.vertices.size() + seeds.size());
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (drop[v]) continue;
    samples.push_back({mesh.vertices[v], mesh.cells[v]});
    sample_vertex.push_back(static_cast<long>(v));
  }
  for (const SkinSample& seed : seeds) {
    samples.push_back(seed);
    sample_vertex.push_back(-1);
  }
  SkinMeshResult made = remesh_skin(complex, samples, criteria);
  RepairResult out;
  if (made.status != MeshingStatus::ok) {
    out.failed_because = made.message;
    return out;
  }
  out.ok = true;
  out.origin.resize(made.mesh.vertices.size());
  for (size_t v = 0; v < out.origin.size(); ++v)
    out.origin[v] = made.origins[v] >= 0 ? sample_vertex[static_cast<size_t>(made.origins[v])] : -1;
  out.counts.insertions = made.stats.inserted_size + made.stats.inserted_shape + made.stats.inserted_distance +
                          made.stats.inserted_topology;
  out.mesh = std::move(made.mesh);
  return out;
}

}  // namespace skinmesh::detail

namespace skinmesh::detail {

namespace {

// The stars of a mesh's vertices, changed by half-edge contractions.
class ContractibleStars {
 public:
  explicit ContractibleStars(const SurfaceMesh& mesh) : mesh_(mesh), stars_(mesh.vertices.size()), alive_(mesh.triangles.size(), 1) {
    for (size_t f = 0; f < mesh.triangles.size(); ++f)
      for (int v : mesh.triangles[f]) stars_[static_cast<size_t>(v)].push_back(static_cast<int>(f));
  }
  const std::vector<char>& alive() const { return alive_; }
  std::vector<int> ring(int v) const {
    std::vector<int> out;
    for (int f : stars_[static_cast<size_t>(v)])
      for (int w : mesh_.triangles[static_cast<size_t>(f)])
        if (w != v) out.push_back(w);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }
  // `gone` merged into `kept` (contract, mesh_part.hpp's conditions); false, nothing changed, where they fail.
  bool contract(int gone, int kept, SurfaceMesh& mesh) {
    std::vector<int> shared;  // the triangles on the edge
    for (int f : stars_[static_cast<size_t>(gone)])
      if (has(f, kept)) shared.push_back(f);
    if (shared.size() != 2) return false;
    const std::vector<int> around_gone = ring(gone), around_kept = ring(kept);
    if (around_gone.size() < 3 || around_kept.size() < 3 || around_gone.size() + around_kept.size() < 8) return false;
    std::vector<int> common;
    std::set_intersection(around_gone.begin(), around_gone.end(), around_kept.begin(), around_kept.end(),
                          std::back_inserter(common));
    if (common.size() != 2) return false;
    for (int c : common)
      if (stars_[static_cast<size_t>(c)].size() < 4) return false;
    for (int f : shared) {
      alive_[static_cast<size_t>(f)] = 0;
      for (int v : mesh.triangles[static_cast<size_t>(f)]) drop_from_star(v, f);
    }
    for (int f : stars_[static_cast<size_t>(gone)]) {
      std::replace(mesh.triangles[static_cast<size_t>(f)].begin(), mesh.triangles[static_cast<size_t>(f)].end(), gone,
                   kept);
      stars_[static_cast<size_t>(kept)].push_back(f);
    }
    stars_[static_cast<size_t>(gone)].clear();
    return true;
  }

 private:
  bool has(int f, int v) const {
    const auto& t = mesh_.triangles[static_cast<size_t>(f)];
    return t[0] == v || t[1] == v || t[2] == v;
  }
  void drop_from_star(int v, int f) {
    auto& star = stars_[static_cast<size_t>(v)];
    star.erase(std::remove(star.begin(), star.end(), f), star.end());
  }
  const SurfaceMesh& mesh_;  // the mesh being contracted (its triangles change)
  std::vector<std::vector<int>> stars_;
  std::vector<char> alive_;
};

}  // namespace

bool merge_lost_vertices(SurfaceMesh& mesh, std::vector<char>& lost, std::vector<int>& kept_from,
                         std::vector<char>& touched) {
  kept_from.clear();
  touched.clear();
  SurfaceMesh work = mesh;
  ContractibleStars stars(work);
  std::vector<char> left = lost;
  std::vector<int> pending, merged_into;
  for (size_t v = 0; v < left.size(); ++v)
    if (left[v]) pending.push_back(static_cast<int>(v));
  // A lost vertex whose neighbours are all lost waits for one of them to go.
  bool progress = true;
  while (!pending.empty() && progress) {
    progress = false;
    std::vector<int> still;
    for (int v : pending) {
      std::vector<std::pair<double, int>> nearest;
      for (int w : stars.ring(v))
        if (!left[static_cast<size_t>(w)])
          nearest.emplace_back((work.vertices[static_cast<size_t>(w)] - work.vertices[static_cast<size_t>(v)]).squaredNorm(), w);
      std::sort(nearest.begin(), nearest.end());
      bool merged = false;
      int into = -1;
      for (const auto& [distance, w] : nearest)
        if ((merged = stars.contract(v, w, work))) {
          into = w;
          break;
        }
      if (merged) {
        merged_into.push_back(into);
        left[static_cast<size_t>(v)] = 0;
        progress = true;
      } else {
        still.push_back(v);
      }
    }
    pending = std::move(still);
  }
  if (!pending.empty()) return false;
  std::vector<char> changed(work.vertices.size(), 0);  // the merged-into vertices and their neighbours
  for (int w : merged_into) {
    changed[static_cast<size_t>(w)] = 1;
    for (int u : stars.ring(w)) changed[static_cast<size_t>(u)] = 1;
  }
  mesh = used_part(work, stars.alive(), kept_from);
  lost.assign(mesh.vertices.size(), 0);
  for (int v : kept_from) touched.push_back(changed[static_cast<size_t>(v)]);
  return true;
}

}  // namespace skinmesh::detail
