// Stereo disparity at chosen pixels of a rectified pair, not at every pixel: the front end uses
// the depth of its cloud's points, the feature tracker's corners and the disparity offset
// estimate's tracks, a few percent of the image (issue 42). Each pixel's disparity is the best
// block match (sum of absolute differences of the x-derivative images, as SGBM's prefilter makes
// them, over a block_size square) along its epipolar line, kept only when it is unique in its
// search interval and the match back from the right image (a left-right check) lands within
// max_lr_difference of it, then refined to sub-pixel by a parabola through the costs of a wider
// refine_width x refine_height window at it and its two neighbours (moved by one where that
// window's costs are lower beside it). The search interval:
//   coarse_level 0: the whole disparity range (a sparse epipolar matcher);
//   coarse_level 1 or 2: SGBM of the pair at 1/2 or 1/4 of the resolution once per pair, then at
//     each pixel the span of the coarse disparities around it, widened by search_radius px at
//     full resolution (where SGBM has none around the pixel: no disparity). The coarse SGBM's
//     own left-right check drops most occluded pixels before the full-resolution one does.
#pragma once

#include <functional>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

namespace cvo {

struct PointMatcherOptions {
  int min_disparity = 0;
  int num_disparities = 128;  // the range searched: [min_disparity, min + num)
  int block_size = 5;         // odd: the search window's width and height
  int refine_width = 15;      // odd, <= 15: the sub-pixel window's width (0: the search window)
  int refine_height = 5;      // odd: its height
  int coarse_level = 2;       // 0: whole range; 1, 2: SGBM at 1/2, 1/4 of the resolution
  int search_radius = 3;      // px at full resolution beyond the coarse disparities' span
  int prefilter_cap = 63;     // the x-derivative clipped to [-cap, cap], as SGBM's prefilter
  int uniqueness_ratio = 5;   // % a match's cost must beat every other (beyond +-1 px) by
  int max_lr_difference = 1;  // px between the disparity and the right image's match back

  // Throws std::invalid_argument naming the option that makes no sense.
  void validate() const;
};

class PointStereoMatcher {
 public:
  explicit PointStereoMatcher(const PointMatcherOptions& options);

  // Prepares the pair for matching at pixels of rows [first_row, rows): the x-derivative images
  // and, with a coarse level, the coarse SGBM disparity of those rows. `left`, `right`: 8-bit
  // grey (or BGR, converted), rectified, of one size. Throws std::invalid_argument, naming the
  // problem, for empty images, different sizes or types or first_row outside the image.
  // `beside`, when given, runs on OpenCV's threads beside the preparation (the caller's own
  // work on the pair, e.g. finding the pixels to match); its exception is rethrown here.
  void prepare(const cv::Mat& left, const cv::Mat& right, int first_row = 0,
               const std::function<void()>& beside = {});
  bool prepared() const { return !left_.empty(); }
  cv::Size size() const { return size_; }

  // The disparity (px, left image) at each pixel, NaN where it has none: its window leaves the
  // prepared rows or the image, no disparity of the range fits in the right image, the coarse
  // disparity has none around it, or the match is not unique or fails the left-right check.
  // Throws std::logic_error before prepare(), std::invalid_argument for a pixel outside the
  // image. Splits the pixels over OpenCV's threads.
  std::vector<float> match(const std::vector<cv::Point>& pixels) const;
  float match(cv::Point pixel) const;

  const PointMatcherOptions& options() const { return options_; }

 private:
  // The interval [lo, hi] of disparities searched at (x, y); false when there is none.
  bool searchInterval(int x, int y, int* lo, int* hi) const;
  float matchOne(int x, int y, std::vector<std::uint16_t>& costs) const;
  // Sub-pixel disparity around the integer `best` with the refinement window; NaN where its
  // costs have no minimum within one pixel of it.
  float refine(int x, int y, int best, int lo, int hi, const std::uint16_t* costs, int top) const;

  PointMatcherOptions options_;
  cv::Ptr<cv::StereoSGBM> coarse_sgbm_;
  cv::Size size_;
  int first_row_ = 0;
  int pad_ = 0;           // columns of padding left of the images (right: 32 + block / 2)
  cv::Mat left_, right_;  // x-derivative images, padded: pixel (x, y) at (x + pad_, y - row0_)
  int row0_ = 0;          // the first image row the padded images hold
  cv::Mat coarse_;        // CV_16S, SGBM's fixed point (x16), rows from first_row_
};

}  // namespace cvo
