// A rectified stereo pair (or a left image with a given disparity image) to a labeled cloud in
// the left camera's optical frame.
#pragma once

#include <opencv2/core.hpp>

#include "cvo_odometry/frontend/depth_cloud_builder.hpp"
#include "cvo_odometry/frontend/stereo_matcher.hpp"

namespace cvo {

struct StereoFrontendOptions {
  StereoMatcherOptions matcher;
  double disparity_scale = 1.0;   // stored disparity value -> pixels (given disparity images)
  double disparity_offset = 0.0;  // pixels added to every disparity (a calibration correction)
  CloudBuilderOptions cloud;
};

struct StereoFrame {
  cv::Mat left;       // 8-bit BGR or grey, rectified
  cv::Mat right;      // may be empty when `disparity` is given
  cv::Mat disparity;  // optional: disparity of `left` (see disparity_scale); skips matching
  PinholeIntrinsics intrinsics;  // of the rectified left image
  double baseline = 0.0;         // metres, > 0
  cv::Mat semantics;             // optional: class ids or class probabilities
};

class StereoCloudBuilder {
 public:
  explicit StereoCloudBuilder(const StereoFrontendOptions& options);

  // Throws std::invalid_argument naming the problem (no right image and no disparity, sizes that
  // differ, a baseline or intrinsics that make no sense, no valid depth, ...).
  LabeledCloud build(const StereoFrame& frame, FrontendStats* stats = nullptr,
                     FrameImages* images = nullptr);

  // Depth in metres (CV_32FC1, NaN invalid or nearer than min_depth; beyond max_depth kept) of
  // the frame, from its disparity or by matching;
  // matching leaves the rows above crop_top_rows NaN (never used) but for 16 rows of context.
  cv::Mat depth(const StereoFrame& frame) const;

  const StereoFrontendOptions& options() const { return options_; }
  // From the next frame on (a self-calibrated value); throws std::invalid_argument if not finite.
  void setDisparityOffset(double offset);

 private:
  StereoFrontendOptions options_;
  StereoMatcher matcher_;
  DepthCloudBuilder cloud_builder_;
};

}  // namespace cvo
