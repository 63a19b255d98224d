// Projection of camera-frame points to pixels for the photometric stage: pinhole with the
// plumb_bob (k1 k2 p1 p2 [k3]) or rational (k1 k2 p1 p2 k3 k4 k5 k6) distortion of ROS
// camera_info, so that an unrectified image (TUM fr1) is sampled where the point really shows.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

namespace cvo {

class CameraModel {
 public:
  CameraModel() = default;
  // Throws std::invalid_argument for a non-positive or non-finite focal length, or a
  // distortion coefficient count other than 0, 4, 5 or 8.
  CameraModel(double fx, double fy, double cx, double cy, const std::vector<double>& distortion);

  // Pixel (u, v) of a point with z > 0.
  Eigen::Vector2d project(const Eigen::Vector3d& point) const;
  // d(u, v) / d(point) of the pinhole part (distortion left out: used as the Gauss-Newton
  // Jacobian, the residuals themselves use project()).
  Eigen::Matrix<double, 2, 3> pinholeJacobian(const Eigen::Vector3d& point) const;

  double fx() const { return fx_; }
  double fy() const { return fy_; }
  // True when a coefficient count is one project() supports.
  static bool supportsDistortion(std::size_t coefficients);

 private:
  double fx_ = 1.0, fy_ = 1.0, cx_ = 0.0, cy_ = 0.0;
  std::array<double, 8> k_{};  // k1 k2 p1 p2 k3 k4 k5 k6, zeros where absent
};

// Inline: the photometric stage projects every point each iteration.
inline Eigen::Vector2d CameraModel::project(const Eigen::Vector3d& p) const {
  const double x = p.x() / p.z(), y = p.y() / p.z();
  const double r2 = x * x + y * y;
  const double radial = (1.0 + r2 * (k_[0] + r2 * (k_[1] + r2 * k_[4]))) /
                        (1.0 + r2 * (k_[5] + r2 * (k_[6] + r2 * k_[7])));
  const double xd = x * radial + 2.0 * k_[2] * x * y + k_[3] * (r2 + 2.0 * x * x);
  const double yd = y * radial + k_[2] * (r2 + 2.0 * y * y) + 2.0 * k_[3] * x * y;
  return {fx_ * xd + cx_, fy_ * yd + cy_};
}

inline Eigen::Matrix<double, 2, 3> CameraModel::pinholeJacobian(const Eigen::Vector3d& p) const {
  const double inv_z = 1.0 / p.z();
  Eigen::Matrix<double, 2, 3> J;
  J << fx_ * inv_z, 0.0, -fx_ * p.x() * inv_z * inv_z, 0.0, fy_ * inv_z,
      -fy_ * p.y() * inv_z * inv_z;
  return J;
}

}  // namespace cvo
