// A rectified stereo pair (or a left image with a given disparity image) to a labeled cloud in
// the left camera's optical frame.
#pragma once

#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "cvo_odometry/core/motion_prior.hpp"
#include "cvo_odometry/frontend/depth_cloud_builder.hpp"
#include "cvo_odometry/frontend/point_stereo_matcher.hpp"
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
  // A point mode (matcher.depth quarter, half or sparse) matches only the pixels the front end
  // uses (pointPixels()); every other pixel is NaN.
  cv::Mat depth(const StereoFrame& frame) const;

  // Point modes: the pixels of a frame matched: FAST corners (no non-maximum suppression) of
  // the rows below crop_top_rows at a threshold a little below the one the cloud's FAST
  // selection used last (so that it finds the same corners with depth, and the feature tracker
  // its corners among them), with a grid for the grid and mixed selectors.
  std::vector<cv::Point> pointPixels(const cv::Mat& grey) const;

  // Point modes: depth for the 3x3 neighbourhoods of the prior's tracks, where the disparity
  // offset estimate reads it, in the depth images of the last two frames build() made (their
  // pixels in the current image, and their corners' pixels in the previous one), written into
  // those images (the FrameImages build() handed out share them). Does nothing in dense mode.
  void completeTrackDepth(const MotionPrior& prior, const PinholeIntrinsics& intrinsics);

  const StereoFrontendOptions& options() const { return options_; }
  // From the next frame on (a self-calibrated value); throws std::invalid_argument if not finite.
  void setDisparityOffset(double offset);

 private:
  // A matched frame's prepared pair and depth image, kept for completeTrackDepth().
  struct PointFrame {
    std::unique_ptr<PointStereoMatcher> matcher;
    cv::Mat depth;
    double focal_baseline = 0.0;
    double offset = 0.0;
  };
  void checkFrame(const StereoFrame& frame) const;
  // The depth of `frame` by point matching with `matcher`.
  cv::Mat pointDepth(const StereoFrame& frame, PointStereoMatcher& matcher) const;
  // Matches the NaN pixels of `depth` among `pixels` (those inside it) with `matcher` (prepared
  // with the pair `depth` belongs to) and writes their depth, at `offset` px of disparity offset.
  void completeDepth(const PointStereoMatcher& matcher, double focal_baseline, double offset,
                     const std::vector<cv::Point>& pixels, cv::Mat& depth) const;

  // A NaN depth image of `size`, in a buffer of earlier frames that nobody holds any more.
  cv::Mat depthBuffer(cv::Size size) const;

  StereoFrontendOptions options_;
  StereoMatcher matcher_;
  mutable std::vector<cv::Mat> depth_buffers_;
  DepthCloudBuilder cloud_builder_;
  PointMatcherOptions point_options_;
  int fast_threshold_ = 0;  // the cloud's FAST selection's last threshold
  PointFrame current_, previous_;
};

}  // namespace cvo
