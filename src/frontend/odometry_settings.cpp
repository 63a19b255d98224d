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
  if (!(point_spacing >= 0.0 && point_spacing <= 2.0)) {
    throw std::invalid_argument("point_spacing must be in [0, 2] (a fraction of ell_min)");
  }
  if (!std::isfinite(disparity_offset)) {
    throw std::invalid_argument("disparity_offset must be finite");
  }
  DisparityOffsetEstimator check(disparity_offset_estimate);  // throws on options out of range
}

CloudBuilderOptions OdometrySettings::cloudOptions() const {
  CloudBuilderOptions options = cloud;
  if (!cvo.photometric_rotation) options.image_levels = 0;
  options.min_point_spacing = point_spacing * cvo.ell_min;
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

FeatureTrackerOptions OdometrySettings::trackerOptions() const {
  FeatureTrackerOptions options = features;
  options.object_apart_px = cvo.moving_min_px;
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
