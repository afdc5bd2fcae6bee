#include "skinmesh/morph/relaxation.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <vector>

namespace skinmesh {

namespace {

// The vertices a relaxation may move (every vertex, or those `movable`
// marks) with their neighbours in compressed rows: each edge once per end,
// in the order of the triangles, so a neighbour shared by two triangles
// counts twice, which weighs the centroid like the triangles around the
// vertex. Rows for the movable vertices alone: the moving-balls engine
// relaxes a few hundred corners of a mesh of a quarter of a million
// triangles, and rows for every vertex cost more than moving them.
struct Movers {
  std::vector<int> vertex;            // the vertices that may move, ascending
  std::vector<int> offsets, indices;  // neighbours of vertex[i]: indices[offsets[i] .. offsets[i + 1])
};

Movers movers(const SurfaceMesh& mesh, const std::vector<char>* movable) {
  const size_t n = mesh.vertices.size();
  Movers m;
  std::vector<int> row(n, -1);
  for (size_t v = 0; v < n; ++v)
    if (!movable || (*movable)[v]) {
      row[v] = static_cast<int>(m.vertex.size());
      m.vertex.push_back(static_cast<int>(v));
    }
  m.offsets.assign(m.vertex.size() + 1, 0);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const int r = row[static_cast<size_t>(t[static_cast<size_t>(k)])];
      if (r >= 0) m.offsets[static_cast<size_t>(r) + 1] += 2;
    }
  for (size_t r = 0; r + 1 < m.offsets.size(); ++r) m.offsets[r + 1] += m.offsets[r];
  m.indices.assign(static_cast<size_t>(m.offsets.back()), 0);
  std::vector<int> fill(m.offsets.begin(), m.offsets.end() - 1);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const int r = row[static_cast<size_t>(t[static_cast<size_t>(k)])];
      if (r < 0) continue;
      m.indices[static_cast<size_t>(fill[static_cast<size_t>(r)]++)] = t[static_cast<size_t>((k + 1) % 3)];
      m.indices[static_cast<size_t>(fill[static_cast<size_t>(r)]++)] = t[static_cast<size_t>((k + 2) % 3)];
    }
  return m;
}

}  // namespace

long relax_tangentially(const SkinComplex& complex, SurfaceMesh& mesh, const RelaxationOptions& options,
                        const std::vector<char>* movable) {
  const Movers m = movers(mesh, movable);
  const size_t n = mesh.vertices.size(), count = m.vertex.size();
  // Jacobi passes: every place of a pass is worked out from the places
  // before it, then all are written.
  std::vector<Eigen::Vector3d> points(count);
  std::vector<int> cells(count);
  std::atomic<long> refused{0};
  if (mesh.normals.size() != n) {
    mesh.normals.resize(n);
    for (size_t v = 0; v < n; ++v) mesh.normals[v] = complex.evaluate(mesh.vertices[v], mesh.cells[v]).gradient.normalized();
  }
  std::vector<char> moved(count);  // per pass: the vertex moved (its normal is evaluated again)
  for (int pass = 0; pass < options.passes; ++pass) {
    std::fill(moved.begin(), moved.end(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 256), [&](const tbb::blocked_range<size_t>& r) {
      long refused_here = 0;
      for (size_t i = r.begin(); i != r.end(); ++i) {
        const size_t v = static_cast<size_t>(m.vertex[i]);
        points[i] = mesh.vertices[v];
        cells[i] = mesh.cells[v];
        const int begin = m.offsets[i], end = m.offsets[i + 1];
        if (begin == end) continue;
        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        double spacing = 0;  // mean distance to the neighbours
        for (int k = begin; k < end; ++k) {
          const Eigen::Vector3d& u = mesh.vertices[static_cast<size_t>(m.indices[static_cast<size_t>(k)])];
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
        points[i] = p.point;
        cells[i] = p.cell;
        moved[i] = 1;
      }
      refused += refused_here;
    });
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 512), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) {
        if (!moved[i]) continue;
        const size_t v = static_cast<size_t>(m.vertex[i]);
        mesh.vertices[v] = points[i];
        mesh.cells[v] = cells[i];
        mesh.normals[v] = complex.evaluate(mesh.vertices[v], mesh.cells[v]).gradient.normalized();
      }
    });
  }
  return refused.load();
}

}  // namespace skinmesh
