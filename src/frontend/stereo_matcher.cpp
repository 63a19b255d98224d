#include "cvo_odometry/frontend/stereo_matcher.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include "cvo_odometry/frontend/color_features.hpp"

namespace cvo {

void StereoMatcherOptions::validate() const {
  if (num_disparities < 16 || num_disparities % 16 != 0) {
    throw std::invalid_argument("num_disparities must be a positive multiple of 16, got " +
                                std::to_string(num_disparities));
  }
  if (block_size < 1 || block_size % 2 == 0 || block_size > 21) {
    throw std::invalid_argument("block_size must be odd and in [1, 21], got " +
                                std::to_string(block_size));
  }
  if (p1 < 0 || p2 < 0 || (p2 > 0 && p2 <= p1)) {
    throw std::invalid_argument("SGBM penalties need 0 <= p1 < p2 (or 0 for the defaults)");
  }
  if (uniqueness_ratio < 0 || uniqueness_ratio > 99) {
    // sgbm_3way divides by 100 - uniqueness_ratio
    throw std::invalid_argument("uniqueness_ratio must be in [0, 99], got " +
                                std::to_string(uniqueness_ratio));
  }
  if (mode != "sgbm" && mode != "hh" && mode != "sgbm_3way") {
    throw std::invalid_argument("unknown SGBM mode '" + mode + "' (sgbm, hh or sgbm_3way)");
  }
  if (depth != "dense" && depth != "quarter" && depth != "half" && depth != "sparse") {
    throw std::invalid_argument("unknown stereo_depth '" + depth +
                                "' (dense, quarter, half or sparse)");
  }
}

int StereoMatcherOptions::pointLevel() const {
  return depth == "quarter" ? 2 : depth == "half" ? 1 : depth == "sparse" ? 0 : -1;
}

int StereoMatcherOptions::minImageWidth() const {
  // 64-bit: min_disparity + num_disparities may not fit an int.
  const long long max_disparity = static_cast<long long>(min_disparity) + num_disparities;
  const long long width =
      std::max(max_disparity, 0LL) - std::min(min_disparity, 0) + block_size / 2 + 1;
  return static_cast<int>(std::min<long long>(width, std::numeric_limits<int>::max()));
}

void StereoMatcherOptions::checkImageSize(int cols, int rows) const {
  if (cols < 1 || rows < 1) {
    throw std::invalid_argument("stereo image is empty (" + std::to_string(cols) + "x" +
                                std::to_string(rows) + ")");
  }
  if (cols < minImageWidth()) {
    throw std::invalid_argument(
        "stereo pair is " + std::to_string(cols) + "x" + std::to_string(rows) + " but SGBM (" +
        mode + ", min_disparity " + std::to_string(min_disparity) + ", num_disparities " +
        std::to_string(num_disparities) + ", block_size " + std::to_string(block_size) +
        ") needs images at least " + std::to_string(minImageWidth()) +
        " pixels wide (more than max(min_disparity + num_disparities, 0) - min(min_disparity, "
        "0) + block_size / 2): lower num_disparities or use wider images");
  }
}

StereoMatcher::StereoMatcher(const StereoMatcherOptions& options) : options_(options) {
  options_.validate();
  const int area = options_.block_size * options_.block_size;
  const int mode = options_.mode == "hh"          ? cv::StereoSGBM::MODE_HH
                   : options_.mode == "sgbm_3way" ? cv::StereoSGBM::MODE_SGBM_3WAY
                                                  : cv::StereoSGBM::MODE_SGBM;
  sgbm_ = cv::StereoSGBM::create(
      options_.min_disparity, options_.num_disparities, options_.block_size,
      options_.p1 > 0 ? options_.p1 : 8 * area, options_.p2 > 0 ? options_.p2 : 32 * area,
      options_.disp12_max_diff, options_.pre_filter_cap, options_.uniqueness_ratio,
      options_.speckle_window_size, options_.speckle_range, mode);
}

void checkStereoPair(const cv::Mat& left, const cv::Mat& right) {
  if (left.empty() || right.empty()) throw std::invalid_argument("stereo image is empty");
  if (left.size() != right.size()) {
    throw std::invalid_argument("left image is " + std::to_string(left.cols) + "x" +
                                std::to_string(left.rows) + " but right is " +
                                std::to_string(right.cols) + "x" + std::to_string(right.rows));
  }
}

cv::Mat StereoMatcher::disparity(const cv::Mat& left, const cv::Mat& right) const {
  checkStereoPair(left, right);
  // Before OpenCV, which would not refuse it (StereoMatcherOptions::minImageWidth).
  options_.checkImageSize(left.cols, left.rows);
  cv::Mat fixed_point;  // CV_16S, disparity * 16
  sgbm_->compute(toGrey(left), toGrey(right), fixed_point);
  cv::Mat pixels(fixed_point.size(), CV_32FC1);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const int invalid_below = options_.min_disparity * 16;  // SGBM marks failures with min - 1
  for (int v = 0; v < fixed_point.rows; ++v) {
    const auto* in = fixed_point.ptr<std::int16_t>(v);
    auto* out = pixels.ptr<float>(v);
    for (int u = 0; u < fixed_point.cols; ++u)
      out[u] = in[u] < invalid_below ? nan : in[u] / 16.0f;
  }
  return pixels;
}

}  // namespace cvo
