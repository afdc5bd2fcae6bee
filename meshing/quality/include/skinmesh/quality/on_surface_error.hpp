// How far mesh vertices are from the skin, measured by the oracle of
// docs/math.md section 2 (one convex minimisation per point), which is
// independent of the mixed complex the mesher works on.
#pragma once

#include "skinmesh/core/balls.hpp"

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <functional>
#include <vector>

namespace skinmesh {

class SkinOracle;  // skin_oracle.hpp

struct SurfaceError {
  double max = 0.0, mean = 0.0;  // Angstrom: |F(x)| / |grad F(x)| over the vertices
  long uncertified = 0;          // vertices where the oracle could not certify its answer
};

// A point's distance to the skin by an oracle (Angstrom), and whether the
// oracle certified it.
struct SkinDistance {
  double distance = 0;
  bool certified = false;
  // The static oracle's OracleResult::reach (Angstrom): the answer stands
  // for any balls that agree within it of the point and weigh no more.
  double reach = INFINITY;
};
// Where an oracle's solve starts at a point: up to four of the skin's balls
// (indices, -1 for none; a mesher's vertex: the balls of its mixed cell).
// An oracle certifies its answer whatever the start: a good one only makes
// it faster.
using OracleStart = std::array<int, 4>;
inline constexpr OracleStart kNoStart{{-1, -1, -1, -1}};
using PointOracle = std::function<SkinDistance(const Eigen::Vector3d&, const OracleStart&)>;

// The static oracle (docs/math.md section 2) as a PointOracle; `oracle` must outlive it.
PointOracle point_oracle(const SkinOracle& oracle);

// Per vertex, its distance by `oracle`, in parallel over the vertices;
// `starts`: per vertex, or empty (kNoStart for every vertex).
std::vector<SkinDistance> oracle_distances(const std::vector<Eigen::Vector3d>& vertices, const PointOracle& oracle,
                                           const std::vector<OracleStart>& starts = {});

// The static oracle's distances (SkinOracle), summarised; in parallel over the vertices.
SurfaceError on_surface_error(const std::vector<Eigen::Vector3d>& vertices, const std::vector<Ball>& balls,
                              double shrink);

}  // namespace skinmesh
