// The on-surface error of mesh vertices, measured by the oracle of
// docs/math.md section 2 (never by the mixed complex the mesher used).
#include "skinmesh/quality/on_surface_error.hpp"

#include "skinmesh/core/skin_oracle.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>

namespace skinmesh {

SurfaceError on_surface_error(const std::vector<Eigen::Vector3d>& vertices, const std::vector<Ball>& balls,
                              double shrink) {
  const SkinOracle oracle(balls, shrink);
  const SurfaceError total = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, vertices.size(), 1024), SurfaceError{},
      [&](const tbb::blocked_range<size_t>& range, SurfaceError acc) {
        for (size_t i = range.begin(); i != range.end(); ++i) {
          const OracleResult o = oracle.evaluate(vertices[i]);
          const double d = o.distance();
          acc.max = std::max(acc.max, d);
          acc.mean += d;  // a sum until the end
          acc.uncertified += !o.certified;
        }
        return acc;
      },
      [](SurfaceError a, const SurfaceError& b) {
        a.max = std::max(a.max, b.max);
        a.mean += b.mean;
        a.uncertified += b.uncertified;
        return a;
      });
  SurfaceError out = total;
  out.mean = vertices.empty() ? 0.0 : total.mean / static_cast<double>(vertices.size());
  return out;
}

}  // namespace skinmesh
