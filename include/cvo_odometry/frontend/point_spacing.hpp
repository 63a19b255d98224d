// Keeps a frame's points apart: at most one in each cube of a given edge, the first offered.
// Pixels chosen evenly in the image crowd together in 3D on near surfaces, and every point adds
// its kernel pairs to each registration sum: a scene at a third of the distance costs 7-8 times
// the registration time (README "Point spacing").
#pragma once

#include <cstddef>

#include <Eigen/Core>

#include "cvo_odometry/core/cell_hash_table.hpp"

namespace cvo {

class PointSpacing {
 public:
  // `spacing`: the cube's edge in metres (0: every point admitted); `points`: how many points
  // will be offered at most. Throws std::invalid_argument for a negative or non-finite spacing.
  PointSpacing(double spacing, std::size_t points);

  // True for the first point offered in its cube; always when the spacing is 0, and for a point
  // too far out to name its cube (beyond 2^20 edges on an axis, or not finite).
  bool admit(const Eigen::Vector3f& point);

 private:
  double inverse_spacing_ = 0.0;
  CellHashTable occupied_;
};

}  // namespace cvo
