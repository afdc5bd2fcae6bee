// The on-surface error of mesh vertices, measured by the oracle of
// docs/math.md section 2 (never by the mixed complex the mesher used).
#include "skinmesh/quality/on_surface_error.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/skin_oracle.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

namespace skinmesh {

PointOracle point_oracle(const SkinOracle& oracle) {
  return [&oracle](const Eigen::Vector3d& x, const OracleStart& start) {
    const OracleResult o = oracle.evaluate(x, start);
    return SkinDistance{o.distance(), o.certified, o.reach};
  };
}

std::vector<SkinDistance> oracle_distances(const std::vector<Eigen::Vector3d>& vertices, const PointOracle& oracle,
                                           const std::vector<OracleStart>& starts) {
  if (!starts.empty() && starts.size() != vertices.size())
    contract_error("oracle_distances: one start per vertex, or none");
  std::vector<SkinDistance> out(vertices.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, vertices.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) out[v] = oracle(vertices[v], starts.empty() ? kNoStart : starts[v]);
  });
  return out;
}

SurfaceError on_surface_error(const std::vector<Eigen::Vector3d>& vertices, const std::vector<Ball>& balls,
                              double shrink) {
  const SkinOracle oracle(balls, shrink);
  const std::vector<SkinDistance> d = oracle_distances(vertices, point_oracle(oracle));
  SurfaceError e;
  for (const SkinDistance& p : d) {
    e.max = std::max(e.max, p.distance);
    e.mean += p.distance;  // a sum until the end
    e.uncertified += !p.certified;
  }
  e.mean = vertices.empty() ? 0.0 : e.mean / static_cast<double>(vertices.size());
  return e;
}

}  // namespace skinmesh
