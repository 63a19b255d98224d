#pragma once

#include <utility>

#include <opencv2/core.hpp>

namespace cvo {

// Depth image to 32-bit float metres with NaN where there is no valid depth. Accepts CV_16UC1
// (divided by `units_per_metre`: 1000 for ROS 16UC1 millimetres, 5000 for TUM PNGs) and CV_32FC1
// (metres). Zero, NaN, inf and depths outside [min_depth, max_depth] become NaN. Other types
// throw std::invalid_argument naming the type.
cv::Mat depthToMetres(const cv::Mat& depth, double units_per_metre, double min_depth,
                      double max_depth);

// The floats that bound [min_depth, max_depth] (the least float >= min_depth, the greatest <=
// max_depth): comparing float depths with them keeps exactly the depths within the doubles
// (an infinite max_depth becomes the largest float: +inf depths are dropped).
std::pair<float, float> floatDepthRange(double min_depth, double max_depth);

}  // namespace cvo

namespace cvo {

// Disparity image to 32-bit float metres (z = focal_times_baseline / d) with NaN where there is
// no valid depth. `disparity_scale` turns stored values into pixels: 1 for CV_32F pixels (as
// stereo_msgs/DisparityImage carries) and plain 8-bit images, 1/16 for OpenCV's CV_16S fixed
// point, 1/256 for KITTI's 16-bit PNGs. Non-positive, NaN and inf disparities and depths outside
// [min_depth, max_depth] become NaN; other types throw std::invalid_argument. `disparity_offset`
// (pixels) is added to every valid disparity first: a stereo calibration's correction.
cv::Mat disparityToMetres(const cv::Mat& disparity, double focal_times_baseline,
                          double disparity_scale, double min_depth, double max_depth,
                          double disparity_offset = 0.0);

}  // namespace cvo
