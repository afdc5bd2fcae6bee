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
