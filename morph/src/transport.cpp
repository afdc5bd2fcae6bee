#include "skinmesh/morph/transport.hpp"

#include <cmath>

namespace skinmesh {

TransportedPoint transport(const SkinComplex& from, const SkinComplex& to, int cell, const Eigen::Vector3d& p) {
  // With y = x - z(t), Q_t(x) = (1-s)|(I-P)y|^2 - s|Py|^2 + s(1-s) R2(t) and
  // P fixed on (0,1): scaling y by k with k^2 = R2(t1) / R2(t0) maps the zero
  // set at t0 onto the zero set at t1 (eq. 19).
  const MixedCell& c0 = from.cell(cell);
  const MixedCell& c1 = to.cell(cell);
  TransportedPoint out;
  const double ratio = c1.R2 / c0.R2;
  if (!(c0.R2 != 0 && ratio > 0)) {
    out.status = TransportStatus::size_vanished;
    return out;
  }
  out.point = c1.center + (p - c0.center) * std::sqrt(ratio);
  constexpr double kOnBoundary = 1e-9;  // Angstrom-scaled membership slack (rounding on a cell face)
  out.status = to.membership_violation(cell, out.point) <= kOnBoundary ? TransportStatus::in_cell
                                                                         : TransportStatus::left_cell;
  return out;
}

}  // namespace skinmesh
