// Curvature-based sizing: the local length scale of the skin is the radius of
// curvature 1/max|k_i| of the patch (the skin's local feature size is bounded by
// it; Cheng, Dey, Edelsbrunner, Sullivan, "Dynamic skin triangulation", DCG 25
// (2001) use the same rho = 1/max curvature), scaled by epsilon and clamped.
#pragma once

#include "skinmesh/core/skin_complex.hpp"

namespace skinmesh {

struct SizingOptions {
  double epsilon = 0.8;   // target edge length / local radius of curvature (dimensionless)
  double min_size = 0.05; // Angstrom: floor where curvature explodes (a pinching neck)
  double max_size = 3.0;  // Angstrom
};

// 1 / max(|k1|, |k2|) at x in `cell` (Angstrom); infinity on a flat patch.
double local_length(const SkinComplex& complex, const Eigen::Vector3d& x, int cell);

// epsilon * local_length, clamped to [min_size, max_size] (Angstrom).
double target_size(const SkinComplex& complex, const Eigen::Vector3d& x, int cell, const SizingOptions& options);
// The same for a local length already known (Angstrom).
double size_for_length(double length, const SizingOptions& options);

}  // namespace skinmesh
