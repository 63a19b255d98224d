// Disparity of a rectified stereo pair with OpenCV's semi-global block matching.
#pragma once

#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

namespace cvo {

struct StereoMatcherOptions {
  int min_disparity = 0;
  int num_disparities = 128;  // multiple of 16
  int block_size = 5;         // odd
  int p1 = 0;                 // 0: 8 * block_size^2 (OpenCV's suggestion)
  int p2 = 0;                 // 0: 32 * block_size^2
  int disp12_max_diff = 1;
  int pre_filter_cap = 63;
  int uniqueness_ratio = 10;
  int speckle_window_size = 100;
  int speckle_range = 2;
  // sgbm | hh | sgbm_3way. sgbm_3way: OpenCV's multi-threaded variant; on KITTI 06 here it is
  // 2.6x faster than sgbm with lower odometry error (README, the KITTI accuracy table).
  std::string mode = "sgbm_3way";

  void validate() const;
};

class StereoMatcher {
 public:
  explicit StereoMatcher(const StereoMatcherOptions& options);

  // 8-bit grey or BGR rectified images of one size; returns CV_32FC1 disparity in pixels of the
  // left image, NaN where matching failed.
  cv::Mat disparity(const cv::Mat& left, const cv::Mat& right) const;

 private:
  StereoMatcherOptions options_;
  cv::Ptr<cv::StereoSGBM> sgbm_;
};

}  // namespace cvo
