// SO(3) / SE(3) helpers on Eigen: exponential, logarithm, adjoint, hat/vee.
// Twists are ordered [omega; v] (rotation first), the convention of the CVO paper.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace cvo {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

namespace lie {

// [w]x, the cross-product matrix.
Eigen::Matrix3d hat(const Eigen::Vector3d& w);
// Inverse of hat for a skew-symmetric matrix.
Eigen::Vector3d vee(const Eigen::Matrix3d& W);

Eigen::Matrix3d expSO3(const Eigen::Vector3d& omega);
// Rotation vector of R, angle in [0, pi]; stable near 0 and near pi.
Eigen::Vector3d logSO3(const Eigen::Matrix3d& R);
// Left Jacobian of SO(3): J(w) with exp([w;v]) translation = J(w) v.
Eigen::Matrix3d leftJacobianSO3(const Eigen::Vector3d& omega);
Eigen::Matrix3d leftJacobianInverseSO3(const Eigen::Vector3d& omega);

// exp of the twist [omega; v]; for omega -> 0 the translation tends to v (J -> I).
Eigen::Isometry3d expSE3(const Vector6d& xi);
Vector6d logSE3(const Eigen::Isometry3d& T);
// Ad_T, with exp(Ad_T xi) = T exp(xi) T^-1 for twists [omega; v].
Matrix6d adjoint(const Eigen::Isometry3d& T);

// Re-orthonormalise the rotation part (accumulated products drift).
Eigen::Isometry3d orthonormalized(const Eigen::Isometry3d& T);

double rotationAngle(const Eigen::Matrix3d& R);

// The pose at (x, y, z) turned by roll about x, then pitch about y, then yaw about z, all about
// the fixed axes (REP-103; R = Rz(yaw) Ry(pitch) Rx(roll)).
Eigen::Isometry3d fromXyzRpy(double x, double y, double z, double roll, double pitch, double yaw);

}  // namespace lie
}  // namespace cvo
