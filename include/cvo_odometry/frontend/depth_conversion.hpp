#pragma once

#include <opencv2/core.hpp>

namespace cvo {

// Depth image to 32-bit float metres with NaN where there is no valid depth. Accepts CV_16UC1
// (divided by `units_per_metre`: 1000 for ROS 16UC1 millimetres, 5000 for TUM PNGs) and CV_32FC1
// (metres). Zero, NaN, inf and depths outside [min_depth, max_depth] become NaN. Other types
// throw std::invalid_argument naming the type.
cv::Mat depthToMetres(const cv::Mat& depth, double units_per_metre, double min_depth,
                      double max_depth);

}  // namespace cvo
