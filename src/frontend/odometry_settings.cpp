#include "cvo_odometry/frontend/odometry_settings.hpp"

#include <cmath>
#include <stdexcept>

namespace cvo {

void OdometrySettings::validate() const {
  cvo.validate();
  cloud.validate();
  stereo.validate();
  features.validate();
  if (!(depth_scale > 0.0)) throw std::invalid_argument("depth_scale must be positive");
  if (!std::isfinite(disparity_offset)) {
    throw std::invalid_argument("disparity_offset must be finite");
  }
  DisparityOffsetEstimator check(disparity_offset_estimate);  // throws on options out of range
}

CloudBuilderOptions OdometrySettings::cloudOptions() const {
  CloudBuilderOptions options = cloud;
  if (!cvo.photometric_rotation) options.image_levels = 0;
  return options;
}

RgbdFrontendOptions OdometrySettings::rgbdOptions() const {
  RgbdFrontendOptions options;
  options.depth_units_per_metre = depth_scale;
  options.cloud = cloudOptions();
  return options;
}

StereoFrontendOptions OdometrySettings::stereoOptions() const {
  StereoFrontendOptions options;
  options.matcher = stereo;
  options.disparity_offset = disparity_offset;
  options.cloud = cloudOptions();
  return options;
}

OdometrySettings loadOdometrySettings(const std::string& path, const OdometrySettings& base) {
  OdometrySettings settings = base;
  if (path.empty()) {
    settings.validate();
  } else {
    loadSettings(path, &settings);
  }
  return settings;
}

}  // namespace cvo
