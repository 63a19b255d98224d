// Pose uncertainty on SE(3). Convention: a covariance P of pose T (or motion M) is that of the
// right perturbation T = T_hat exp(xi), xi = [rho; phi] (translation first, as ROS orders it),
// in the body frame of T. Composing T_k = T_{k-1} M_k propagates
//   P_k = Ad(M_k^-1) P_{k-1} Ad(M_k^-1)^T + Q_k,
// Ad(T) = [R, [p]x R; 0, R] for [rho; phi]. A nav_msgs/Odometry pose covariance is the same
// uncertainty about the parent frame's axes: rotated by T's rotation (toParentAxes).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cvo_odometry/core/lie_group.hpp"

namespace cvo {

// Ad(T) for [rho; phi] twists: T exp(xi) T^-1 = exp(Ad(T) xi).
Matrix6d translationFirstAdjoint(const Eigen::Isometry3d& T);

// P_k from the reference pose's covariance, the motion reference <- current and its covariance.
Matrix6d propagateCovariance(const Matrix6d& reference, const Eigen::Isometry3d& motion,
                             const Matrix6d& motion_covariance);

// A left-perturbation covariance (M = exp(delta) M_hat, delta in the reference frame, as
// registrationCovariance gives it) as the right perturbation of M.
Matrix6d rightPerturbation(const Eigen::Isometry3d& motion, const Matrix6d& left_covariance);

// The covariance of B M B^-1 for a fixed B (a motion of the camera seen in the base frame, with
// B = base <- camera).
Matrix6d conjugatedCovariance(const Eigen::Isometry3d& B, const Matrix6d& covariance);

// The body-frame covariance of pose T about the parent frame's axes (position error in the
// parent frame, rotation error about its axes), as nav_msgs/Odometry carries it.
Matrix6d toParentAxes(const Eigen::Isometry3d& T, const Matrix6d& body_covariance);

}  // namespace cvo
