// A PNG of an estimated trajectory over its ground truth, seen from above: the two axes along
// which the ground truth moves most, the estimate rigidly aligned (ATE alignment) first.
#pragma once

#include <string>

#include <Eigen/Geometry>

#include "cvo_odometry/core/trajectory.hpp"

namespace cvo {

// Throws std::runtime_error if the file cannot be written.
void plotTrajectories(const std::string& png_path, const Trajectory& ground_truth,
                      const Trajectory& estimate, const Eigen::Isometry3d& estimate_alignment,
                      const std::string& title);

}  // namespace cvo
