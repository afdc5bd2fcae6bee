// Constants of the triangle criteria shared by the criteria themselves
// (triangle_criteria.cpp) and the estimate of their output
// (triangle_estimate.cpp). Private to the mesher.
#pragma once

namespace skinmesh::detail {

// The distance criterion measures the skin's deviation at one point of each
// triangle (its circumcentre's normal line); the deviation elsewhere in the
// triangle is a little larger, so the criterion keeps this margin.
constexpr double kToleranceMargin = 0.7;

}  // namespace skinmesh::detail
