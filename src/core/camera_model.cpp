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

}  // namespace cvo
