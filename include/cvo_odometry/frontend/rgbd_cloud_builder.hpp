// RGB-D images to a labeled cloud in the camera's optical frame (z forward, x right, y down).
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "cvo_odometry/core/labeled_cloud.hpp"
#include "cvo_odometry/frontend/pinhole_intrinsics.hpp"
#include "cvo_odometry/frontend/point_selector.hpp"

namespace cvo {

struct RgbdFrontendOptions {
  double depth_units_per_metre = 1000.0;  // 16UC1 depth: 1000 (ROS, mm) or 5000 (TUM PNG)
  double min_depth = 0.1;                 // metres
  double max_depth = 10.0;
  SelectorOptions selector;
  int semantic_classes = 0;  // > 0: a segmentation image is expected
  std::vector<int> ignore_classes;
};

struct RgbdFrame {
  cv::Mat image;  // 8-bit BGR or grey
  cv::Mat depth;  // 16UC1 (scaled) or 32FC1 (metres), registered to `image`
  PinholeIntrinsics intrinsics;
  cv::Mat semantics;  // optional: class ids or class probabilities
};

struct FrontendStats {
  SelectionStats selection;
  std::size_t valid_depth_pixels = 0;
  double time_ms = 0.0;
};

// Rays (x/z, y/z) through pixel centres, undistorted when the intrinsics carry distortion.
std::vector<cv::Point2f> normalisedRays(const std::vector<cv::Point>& pixels,
                                        const PinholeIntrinsics& intrinsics);

class RgbdCloudBuilder {
 public:
  explicit RgbdCloudBuilder(const RgbdFrontendOptions& options);

  // Throws std::invalid_argument naming the problem: empty images, mismatched sizes, an
  // unsupported encoding, intrinsics that make no sense, or no pixel with valid depth.
  LabeledCloud build(const RgbdFrame& frame, FrontendStats* stats = nullptr);

  const RgbdFrontendOptions& options() const { return options_; }

 private:
  RgbdFrontendOptions options_;
  PointSelector selector_;
};

}  // namespace cvo
