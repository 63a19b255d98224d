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
  // Where the stereo front end computes depth (StereoCloudBuilder):
  //   dense: SGBM (the options above) at every pixel of the rows below the crop;
  //   quarter, half: at the pixels the front end uses only (FAST corners for the cloud and the
  //     feature tracker, the tracks' neighbourhoods for the disparity offset estimate), each
  //     searched around the disparity of SGBM at 1/4 or 1/2 of the resolution, with sub-pixel
  //     refinement and a left-right check (PointStereoMatcher);
  //   sparse: at those pixels, the whole disparity range searched at each (no SGBM at all).
  // The point modes leave every other pixel without depth (NaN).
  std::string depth = "dense";

  void validate() const;
  // The coarse level of a point mode (quarter 2, half 1, sparse 0); -1 for dense.
  int pointLevel() const;

  // The narrowest pair OpenCV 4.6's StereoSGBM can match with these options, in every mode
  // (modules/calib3d/src/stereosgbm.cpp): the matching band, columns minX1 = max(min_disparity
  // + num_disparities, 0) to maxX1 = cols + min(min_disparity, 0) in computeDisparitySGBM (sgbm,
  // hh) and SGBM3WayMainLoop (sgbm_3way), must be wider than block_size / 2. Otherwise
  // sgbm_3way sizes its buffers from the band's negative width (an allocation of ~2^64 bytes),
  // sgbm and hh return no disparity at all when the band is empty, and every mode sums its first
  // block past the band's end (reads of other buffers: results that vary from run to run,
  // OpenCV issue 25828; upstream refuses such pairs since its PR 27305, 2025). No rule on the
  // height (1 row works).
  int minImageWidth() const;
  // Throws std::invalid_argument, naming the sizes and the rule, when a cols x rows pair is
  // one the matcher cannot handle (narrower than minImageWidth(), or empty).
  void checkImageSize(int cols, int rows) const;
};

// Throws std::invalid_argument, naming the problem, when an image of a stereo pair is empty or
// the two differ in size.
void checkStereoPair(const cv::Mat& left, const cv::Mat& right);

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
