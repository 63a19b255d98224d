#include "cvo_odometry/frontend/depth_conversion.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace cvo {

cv::Mat depthToMetres(const cv::Mat& depth, double units_per_metre, double min_depth,
                      double max_depth) {
  if (depth.empty()) throw std::invalid_argument("depth image is empty");
  if (depth.channels() != 1) {
    throw std::invalid_argument("depth image has " + std::to_string(depth.channels()) +
                                " channels; expected 1 (16UC1 or 32FC1)");
  }
  if (!(units_per_metre > 0.0)) throw std::invalid_argument("depth scale must be positive");
  const float nan = std::numeric_limits<float>::quiet_NaN();
  cv::Mat metres(depth.size(), CV_32FC1);
  auto keep = [&](float d) {
    return std::isfinite(d) && d > 0.0f && d >= min_depth && d <= max_depth;
  };
  if (depth.depth() == CV_16U) {
    const float scale = static_cast<float>(1.0 / units_per_metre);
    for (int v = 0; v < depth.rows; ++v) {
      const auto* in = depth.ptr<std::uint16_t>(v);
      auto* out = metres.ptr<float>(v);
      for (int u = 0; u < depth.cols; ++u) {
        const float d = static_cast<float>(in[u]) * scale;
        out[u] = keep(d) ? d : nan;
      }
    }
  } else if (depth.depth() == CV_32F) {
    for (int v = 0; v < depth.rows; ++v) {
      const auto* in = depth.ptr<float>(v);
      auto* out = metres.ptr<float>(v);
      for (int u = 0; u < depth.cols; ++u)
        out[u] = keep(in[u]) ? in[u] : nan;
    }
  } else {
    throw std::invalid_argument("unsupported depth image type " + std::to_string(depth.type()) +
                                "; expected 16UC1 (scaled integers) or 32FC1 (metres)");
  }
  return metres;
}

}  // namespace cvo
