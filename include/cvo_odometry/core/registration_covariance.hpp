// An approximate covariance of a registration result, for the odometry message: the inverse
// Gauss-Newton Hessian of point-to-point alignment of the source cloud at the result, each point
// measured with a standard deviation of the final kernel lengthscale, inflated by 1 / cosine
// (the cosine of the two functions falls as overlap and agreement fall).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cvo_odometry/core/cvo_params.hpp"
#include "cvo_odometry/core/labeled_cloud.hpp"

namespace cvo {

// Order (x, y, z, rotation about x, y, z) as in ROS messages, in the target frame. A cloud with
// fewer than 3 points or a degenerate geometry gives a large diagonal (1e6).
Eigen::Matrix<double, 6, 6> registrationCovariance(const LabeledCloud& source,
                                                   const Eigen::Isometry3d& target_from_source,
                                                   double lengthscale, double cosine);

// The covariance of a motion that was guessed, not measured (a lost frame): over `dt` seconds
// the motion is known only to within the plausible maxima, max_linear_speed * dt and
// max_angular_speed * dt, taken as standard deviations. Same order as above.
Eigen::Matrix<double, 6, 6> guessedMotionCovariance(const CvoParams& params, double dt);

}  // namespace cvo
