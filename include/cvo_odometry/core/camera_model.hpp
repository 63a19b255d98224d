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

}  // namespace cvo
