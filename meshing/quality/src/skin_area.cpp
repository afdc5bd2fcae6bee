#include "skinmesh/quality/skin_area.hpp"

#include <Eigen/Geometry>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>
#include <cmath>
#include <vector>

namespace skinmesh {
namespace {

struct Sums {
  std::array<double, 3> level{0, 0, 0};  // flat area with 1, 4 and 16 sub-triangles per triangle
  long projections = 0;
  bool converged = true;
};

double flat_area(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  return 0.5 * (b - a).cross(c - a).norm();
}

// One triangle: its corners and the points of a 4 x 4 barycentric grid on
// the skin (projected from the flat triangle, each from its nearest
// corner's cell), summed as 1, 4 and 16 flat sub-triangles.
void add_triangle(const SkinComplex& complex, const SurfaceMesh& mesh, const std::array<int, 3>& t, Sums& sums) {
  constexpr int n = 4;
  std::array<std::array<Eigen::Vector3d, n + 1>, n + 1> p;  // p[i][j]: corner weights (n-i-j, i, j) / n
  const Eigen::Vector3d& a = mesh.vertices[static_cast<size_t>(t[0])];
  const Eigen::Vector3d& b = mesh.vertices[static_cast<size_t>(t[1])];
  const Eigen::Vector3d& c = mesh.vertices[static_cast<size_t>(t[2])];
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j) {
      const int k = n - i - j;
      if (k == n) p[i][j] = a;
      else if (i == n) p[i][j] = b;
      else if (j == n) p[i][j] = c;
      else {
        const Eigen::Vector3d flat = (k * a + i * b + j * c) / n;
        const int nearest = k >= i && k >= j ? t[0] : i >= j ? t[1] : t[2];
        const Projection q = complex.project(flat, mesh.cells[static_cast<size_t>(nearest)], 1e-12);
        ++sums.projections;
        sums.converged = sums.converged && q.converged;
        p[i][j] = q.converged ? q.point : flat;
      }
    }
  for (int level = 0, step = n; level < 3; ++level, step /= 2)
    for (int i = 0; i < n; i += step)
      for (int j = 0; i + j < n; j += step) {
        sums.level[static_cast<size_t>(level)] += flat_area(p[i][j], p[i + step][j], p[i][j + step]);
        if (i + j + step < n)  // the downward sub-triangle beside it
          sums.level[static_cast<size_t>(level)] += flat_area(p[i + step][j], p[i + step][j + step], p[i][j + step]);
      }
}

}  // namespace

SkinArea skin_area(const SkinComplex& complex, const SurfaceMesh& mesh) {
  // Per triangle, then summed in order: the same digits whatever the threads.
  std::vector<Sums> per_triangle(mesh.triangles.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, mesh.triangles.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t f = r.begin(); f != r.end(); ++f) add_triangle(complex, mesh, mesh.triangles[f], per_triangle[f]);
  });
  Sums total;
  for (const Sums& s : per_triangle) {
    for (size_t k = 0; k < 3; ++k) total.level[k] += s.level[k];
    total.projections += s.projections;
    total.converged = total.converged && s.converged;
  }
  const double coarse = (4 * total.level[1] - total.level[0]) / 3;
  const double fine = (4 * total.level[2] - total.level[1]) / 3;
  SkinArea out;
  out.area = fine;
  out.uncertainty = std::abs(fine - coarse);
  out.projections = total.projections;
  out.converged = total.converged;
  return out;
}

}  // namespace skinmesh
