// RGB-D images to a labeled cloud in the camera's optical frame (z forward, x right, y down).
#pragma once

#include <opencv2/core.hpp>

#include "cvo_odometry/frontend/depth_cloud_builder.hpp"

namespace cvo {

struct RgbdFrontendOptions {
  double depth_units_per_metre = 1000.0;  // 16UC1 depth: 1000 (ROS, mm) or 5000 (TUM PNG)
  CloudBuilderOptions cloud;
};

struct RgbdFrame {
  cv::Mat image;  // 8-bit BGR or grey
  cv::Mat depth;  // 16UC1 (scaled) or 32FC1 (metres), registered to `image`
  PinholeIntrinsics intrinsics;
  cv::Mat semantics;  // optional: class ids or class probabilities, of `image`
  // The depth image's stamp minus the colour image's (s): where they differ, labelled objects
  // that move are left out with their motion over the gap (LabelTiming).
  double depth_after_colour = 0.0;
};

class RgbdCloudBuilder {
 public:
  explicit RgbdCloudBuilder(const RgbdFrontendOptions& options);

  // Throws std::invalid_argument naming the problem: empty images, mismatched sizes, an
  // unsupported encoding, intrinsics that make no sense, or no pixel with valid depth.
  // `stamp`: the depth image's time (s), as the pipeline's (the colour image's is stamp -
  // depth_after_colour), for the motion of labelled objects.
  LabeledCloud build(const RgbdFrame& frame, FrontendStats* stats = nullptr,
                     FrameImages* images = nullptr, double stamp = 0.0);

  const RgbdFrontendOptions& options() const { return options_; }

 private:
  RgbdFrontendOptions options_;
  DepthCloudBuilder cloud_builder_;
};

}  // namespace cvo
