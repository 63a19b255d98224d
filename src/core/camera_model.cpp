#include "cvo_odometry/core/camera_model.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace cvo {

bool CameraModel::supportsDistortion(std::size_t coefficients) {
  return coefficients == 0 || coefficients == 4 || coefficients == 5 || coefficients == 8;
}

CameraModel::CameraModel(double fx, double fy, double cx, double cy,
                         const std::vector<double>& distortion)
    : fx_(fx), fy_(fy), cx_(cx), cy_(cy) {
  if (!(fx > 0.0) || !(fy > 0.0) || !std::isfinite(fx) || !std::isfinite(fy) ||
      !std::isfinite(cx) || !std::isfinite(cy)) {
    throw std::invalid_argument("camera model: focal lengths must be positive and finite");
  }
  if (!supportsDistortion(distortion.size())) {
    throw std::invalid_argument("camera model: " + std::to_string(distortion.size()) +
                                " distortion coefficients (supported: 0, 4, 5 or 8)");
  }
  for (std::size_t i = 0; i < distortion.size(); ++i) {
    if (!std::isfinite(distortion[i])) {
      throw std::invalid_argument("camera model: non-finite distortion coefficient");
    }
    k_[i] = distortion[i];
  }
}

Eigen::Vector2d CameraModel::project(const Eigen::Vector3d& p) const {
  const double x = p.x() / p.z(), y = p.y() / p.z();
  const double r2 = x * x + y * y;
  const double radial = (1.0 + r2 * (k_[0] + r2 * (k_[1] + r2 * k_[4]))) /
                        (1.0 + r2 * (k_[5] + r2 * (k_[6] + r2 * k_[7])));
  const double xd = x * radial + 2.0 * k_[2] * x * y + k_[3] * (r2 + 2.0 * x * x);
  const double yd = y * radial + k_[2] * (r2 + 2.0 * y * y) + 2.0 * k_[3] * x * y;
  return {fx_ * xd + cx_, fy_ * yd + cy_};
}

Eigen::Matrix<double, 2, 3> CameraModel::pinholeJacobian(const Eigen::Vector3d& p) const {
  const double inv_z = 1.0 / p.z();
  Eigen::Matrix<double, 2, 3> J;
  J << fx_ * inv_z, 0.0, -fx_ * p.x() * inv_z * inv_z, 0.0, fy_ * inv_z,
      -fy_ * p.y() * inv_z * inv_z;
  return J;
}

}  // namespace cvo
