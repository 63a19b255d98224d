#include "cvo_odometry/core/pose_covariance.hpp"

namespace cvo {

Matrix6d translationFirstAdjoint(const Eigen::Isometry3d& T) {
  Matrix6d Ad = Matrix6d::Zero();
  const Eigen::Matrix3d R = T.linear();
  Ad.topLeftCorner<3, 3>() = R;
  Ad.bottomRightCorner<3, 3>() = R;
  Ad.topRightCorner<3, 3>() = lie::hat(T.translation()) * R;
  return Ad;
}

Matrix6d propagateCovariance(const Matrix6d& reference, const Eigen::Isometry3d& motion,
                             const Matrix6d& motion_covariance) {
  const Matrix6d Ad = translationFirstAdjoint(motion.inverse());
  const Matrix6d P = Ad * reference * Ad.transpose() + motion_covariance;
  return 0.5 * (P + P.transpose());
}

Matrix6d rightPerturbation(const Eigen::Isometry3d& motion, const Matrix6d& left_covariance) {
  return conjugatedCovariance(motion.inverse(), left_covariance);
}

Matrix6d conjugatedCovariance(const Eigen::Isometry3d& B, const Matrix6d& covariance) {
  const Matrix6d Ad = translationFirstAdjoint(B);
  const Matrix6d P = Ad * covariance * Ad.transpose();
  return 0.5 * (P + P.transpose());
}

Matrix6d toParentAxes(const Eigen::Isometry3d& T, const Matrix6d& body_covariance) {
  Matrix6d rotate = Matrix6d::Zero();
  rotate.topLeftCorner<3, 3>() = rotate.bottomRightCorner<3, 3>() = T.linear();
  const Matrix6d P = rotate * body_covariance * rotate.transpose();
  return 0.5 * (P + P.transpose());
}

}  // namespace cvo
