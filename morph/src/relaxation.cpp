#include "skinmesh/morph/relaxation.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <vector>

namespace skinmesh {

namespace {

// Neighbours of every vertex in compressed rows (offsets, then indices),
// each edge once per end; a neighbour shared by two triangles counts twice,
// which weighs the centroid like the triangles around the vertex.
void vertex_neighbours(const SurfaceMesh& mesh, std::vector<int>& offsets, std::vector<int>& indices) {
  offsets.assign(mesh.vertices.size() + 1, 0);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) offsets[static_cast<size_t>(t[static_cast<size_t>(k)]) + 1] += 2;
  for (size_t v = 0; v + 1 < offsets.size(); ++v) offsets[v + 1] += offsets[v];
  indices.assign(static_cast<size_t>(offsets.back()), 0);
  std::vector<int> fill(offsets.begin(), offsets.end() - 1);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const size_t v = static_cast<size_t>(t[static_cast<size_t>(k)]);
      indices[static_cast<size_t>(fill[v]++)] = t[static_cast<size_t>((k + 1) % 3)];
      indices[static_cast<size_t>(fill[v]++)] = t[static_cast<size_t>((k + 2) % 3)];
    }
}

}  // namespace

long relax_tangentially(const SkinComplex& complex, SurfaceMesh& mesh, const RelaxationOptions& options,
                        const std::vector<char>* movable) {
  std::vector<int> offsets, indices;
  vertex_neighbours(mesh, offsets, indices);
  const size_t n = mesh.vertices.size();
  std::vector<Eigen::Vector3d> points(n);
  std::vector<int> cells(n);
  std::atomic<long> refused{0};
  if (mesh.normals.size() != n) {
    mesh.normals.resize(n);
    for (size_t v = 0; v < n; ++v) mesh.normals[v] = complex.evaluate(mesh.vertices[v], mesh.cells[v]).gradient.normalized();
  }
  std::vector<char> moved(n);  // per pass: the vertex moved (its normal is evaluated again)
  for (int pass = 0; pass < options.passes; ++pass) {
    std::fill(moved.begin(), moved.end(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 256), [&](const tbb::blocked_range<size_t>& r) {
      long refused_here = 0;
      for (size_t v = r.begin(); v != r.end(); ++v) {
        points[v] = mesh.vertices[v];
        cells[v] = mesh.cells[v];
        const int begin = offsets[v], end = offsets[v + 1];
        if (begin == end || (movable && !(*movable)[v])) continue;
        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        double spacing = 0;  // mean distance to the neighbours
        for (int k = begin; k < end; ++k) {
          const Eigen::Vector3d& u = mesh.vertices[static_cast<size_t>(indices[static_cast<size_t>(k)])];
          centroid += u;
          spacing += (u - mesh.vertices[v]).norm();
        }
        centroid /= static_cast<double>(end - begin);
        spacing /= static_cast<double>(end - begin);
        const Eigen::Vector3d normal = mesh.normals[v];
        Eigen::Vector3d way = centroid - mesh.vertices[v];
        way -= way.dot(normal) * normal;
        if (way.norm() < options.settled_below * spacing) continue;  // settled: stays
        const Projection p = complex.project(mesh.vertices[v] + options.weight * way, mesh.cells[v], 1e-14);
        if (!p.converged || (p.point - mesh.vertices[v]).squaredNorm() > way.squaredNorm()) {
          ++refused_here;
          continue;
        }
        points[v] = p.point;
        cells[v] = p.cell;
        moved[v] = 1;
      }
      refused += refused_here;
    });
    mesh.vertices.swap(points);
    mesh.cells.swap(cells);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 512), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t v = r.begin(); v != r.end(); ++v)
        if (moved[v]) mesh.normals[v] = complex.evaluate(mesh.vertices[v], mesh.cells[v]).gradient.normalized();
    });
  }
  return refused.load();
}

}  // namespace skinmesh
