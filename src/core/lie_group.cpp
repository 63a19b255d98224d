#include "cvo_odometry/core/lie_group.hpp"

#include <cmath>

namespace cvo {
namespace lie {

namespace {
// Below this angle the closed forms lose precision; Taylor series are exact to double rounding.
constexpr double kSmallAngle = 1e-5;
}  // namespace

Eigen::Matrix3d hat(const Eigen::Vector3d& w) {
  Eigen::Matrix3d W;
  W << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
  return W;
}

Eigen::Vector3d vee(const Eigen::Matrix3d& W) {
  return {W(2, 1), W(0, 2), W(1, 0)};
}

Eigen::Matrix3d expSO3(const Eigen::Vector3d& omega) {
  const double theta2 = omega.squaredNorm();
  const double theta = std::sqrt(theta2);
  const Eigen::Matrix3d W = hat(omega);
  double a, b;  // R = I + a W + b W^2
  if (theta < kSmallAngle) {
    a = 1.0 - theta2 / 6.0;
    b = 0.5 - theta2 / 24.0;
  } else {
    a = std::sin(theta) / theta;
    b = (1.0 - std::cos(theta)) / theta2;
  }
  return Eigen::Matrix3d::Identity() + a * W + b * W * W;
}

Eigen::Isometry3d fromXyzRpy(double x, double y, double z, double roll, double pitch, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() << x, y, z;
  return T;
}

double rotationAngle(const Eigen::Matrix3d& R) {
  // atan2 form is accurate over the whole range, unlike acos of the trace.
  const double c = 0.5 * (R.trace() - 1.0);
  const double s = 0.5 * vee(R - R.transpose()).norm();
  return std::atan2(s, c);
}

Eigen::Vector3d logSO3(const Eigen::Matrix3d& R) {
  const double theta = rotationAngle(R);
  const Eigen::Vector3d axis_sin = 0.5 * vee(R - R.transpose());  // = sin(theta) * axis
  if (theta < kSmallAngle) {
    return axis_sin * (1.0 + theta * theta / 6.0);
  }
  if (M_PI - theta > 1e-3) {
    return axis_sin * (theta / std::sin(theta));
  }
  // Near pi sin(theta) vanishes: take the axis from the symmetric part, R + R^T = 2 cos I +
  // 2(1-cos) a a^T.
  const Eigen::Matrix3d B =
      0.5 * (R + R.transpose()) - std::cos(theta) * Eigen::Matrix3d::Identity();
  int k = 0;
  B.diagonal().maxCoeff(&k);
  Eigen::Vector3d axis = B.col(k) / std::sqrt(std::max(B(k, k), 1e-300));
  axis.normalize();
  if (axis.dot(axis_sin) < 0.0) axis = -axis;  // keep the sign consistent with the skew part
  return theta * axis;
}

Eigen::Matrix3d leftJacobianSO3(const Eigen::Vector3d& omega) {
  const double theta2 = omega.squaredNorm();
  const double theta = std::sqrt(theta2);
  const Eigen::Matrix3d W = hat(omega);
  double a, b;  // J = I + a W + b W^2
  if (theta < kSmallAngle) {
    a = 0.5 - theta2 / 24.0;
    b = 1.0 / 6.0 - theta2 / 120.0;
  } else {
    a = (1.0 - std::cos(theta)) / theta2;
    b = (theta - std::sin(theta)) / (theta2 * theta);
  }
  return Eigen::Matrix3d::Identity() + a * W + b * W * W;
}

Eigen::Matrix3d leftJacobianInverseSO3(const Eigen::Vector3d& omega) {
  const double theta2 = omega.squaredNorm();
  const double theta = std::sqrt(theta2);
  const Eigen::Matrix3d W = hat(omega);
  double b;  // J^-1 = I - W/2 + b W^2
  if (theta < kSmallAngle) {
    b = 1.0 / 12.0 + theta2 / 720.0;
  } else {
    b = (1.0 - theta * std::sin(theta) / (2.0 * (1.0 - std::cos(theta)))) / theta2;
  }
  return Eigen::Matrix3d::Identity() - 0.5 * W + b * W * W;
}

Eigen::Isometry3d expSE3(const Vector6d& xi) {
  const Eigen::Vector3d omega = xi.head<3>();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = expSO3(omega);
  T.translation() = leftJacobianSO3(omega) * xi.tail<3>();
  return T;
}

Vector6d logSE3(const Eigen::Isometry3d& T) {
  Vector6d xi;
  const Eigen::Vector3d omega = logSO3(T.linear());
  xi.head<3>() = omega;
  xi.tail<3>() = leftJacobianInverseSO3(omega) * T.translation();
  return xi;
}

Matrix6d adjoint(const Eigen::Isometry3d& T) {
  Matrix6d Ad = Matrix6d::Zero();
  const Eigen::Matrix3d R = T.linear();
  Ad.topLeftCorner<3, 3>() = R;
  Ad.bottomRightCorner<3, 3>() = R;
  Ad.bottomLeftCorner<3, 3>() = hat(T.translation()) * R;
  return Ad;
}

Eigen::Isometry3d orthonormalized(const Eigen::Isometry3d& T) {
  Eigen::Isometry3d out = T;
  out.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
  return out;
}

}  // namespace lie
}  // namespace cvo
