#include "cvo_odometry/frontend/depth_conversion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace cvo {

std::pair<float, float> floatDepthRange(double min_depth, double max_depth) {
  // Clamped first: a double beyond float's range has no defined conversion.
  const double largest = std::numeric_limits<float>::max();
  const float inf = std::numeric_limits<float>::infinity();
  float lo = static_cast<float>(std::clamp(min_depth, -largest, largest));
  float hi = static_cast<float>(std::clamp(max_depth, -largest, largest));
  if (lo < min_depth) lo = std::nextafter(lo, inf);
  if (hi > max_depth) hi = std::nextafter(hi, -inf);
  return {lo, hi};
}

cv::Mat depthToMetres(const cv::Mat& depth, double units_per_metre, double min_depth,
                      double max_depth) {
  if (depth.empty()) throw std::invalid_argument("depth image is empty");
  if (depth.channels() != 1) {
    throw std::invalid_argument("depth image has " + std::to_string(depth.channels()) +
                                " channels; expected 1 (16UC1 or 32FC1)");
  }
  if (!(units_per_metre > 0.0)) throw std::invalid_argument("depth scale must be positive");
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  cv::Mat metres(depth.size(), CV_32FC1);
  // Compared in float: the same depths, and the loops vectorise.
  const std::pair<float, float> range = floatDepthRange(min_depth, max_depth);
  const float lo = range.first, hi = range.second;  // C++17 lambdas capture no bindings
  auto keep = [&](float d) { return d > 0.0f && d < inf && d >= lo && d <= hi; };
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

namespace {

template <typename T>
void disparityRowsToMetres(const cv::Mat& disparity, float numerator, float scale, float offset,
                           float min_depth, float max_depth, cv::Mat* metres) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0; v < disparity.rows; ++v) {
    const T* in = disparity.ptr<T>(v);
    auto* out = metres->ptr<float>(v);
    for (int u = 0; u < disparity.cols; ++u) {
      const float d = static_cast<float>(in[u]) * scale;
      const float z =
          d > 0.0f && std::isfinite(d) && d + offset > 0.0f ? numerator / (d + offset) : nan;
      out[u] = z >= min_depth && z <= max_depth ? z : nan;
    }
  }
}

}  // namespace

cv::Mat disparityToMetres(const cv::Mat& disparity, double focal_times_baseline,
                          double disparity_scale, double min_depth, double max_depth,
                          double disparity_offset) {
  if (disparity.empty()) throw std::invalid_argument("disparity image is empty");
  if (disparity.channels() != 1) {
    throw std::invalid_argument("disparity image has " + std::to_string(disparity.channels()) +
                                " channels; expected 1");
  }
  if (!(focal_times_baseline > 0.0) || !std::isfinite(focal_times_baseline)) {
    throw std::invalid_argument("focal length times baseline must be positive, got " +
                                std::to_string(focal_times_baseline));
  }
  if (!(disparity_scale > 0.0)) throw std::invalid_argument("disparity scale must be positive");
  cv::Mat metres(disparity.size(), CV_32FC1);
  const auto fb = static_cast<float>(focal_times_baseline);
  const auto scale = static_cast<float>(disparity_scale);
  const auto offset = static_cast<float>(disparity_offset);
  if (!std::isfinite(offset)) throw std::invalid_argument("disparity offset must be finite");
  const auto [lo, hi] = floatDepthRange(min_depth, max_depth);
  switch (disparity.depth()) {
    case CV_32F:
      disparityRowsToMetres<float>(disparity, fb, scale, offset, lo, hi, &metres);
      break;
    case CV_16U:
      disparityRowsToMetres<std::uint16_t>(disparity, fb, scale, offset, lo, hi, &metres);
      break;
    case CV_16S:
      disparityRowsToMetres<std::int16_t>(disparity, fb, scale, offset, lo, hi, &metres);
      break;
    case CV_8U:
      disparityRowsToMetres<std::uint8_t>(disparity, fb, scale, offset, lo, hi, &metres);
      break;
    default:
      throw std::invalid_argument("unsupported disparity image type " +
                                  std::to_string(disparity.type()) +
                                  "; expected 32FC1, 16UC1, 16SC1 or 8UC1");
  }
  return metres;
}

}  // namespace cvo
