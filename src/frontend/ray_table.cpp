#include "cvo_odometry/frontend/ray_table.hpp"

#include "cvo_odometry/frontend/depth_cloud_builder.hpp"

namespace cvo {

std::vector<cv::Point2f> RayTable::rays(const std::vector<cv::Point>& pixels,
                                        const PinholeIntrinsics& intrinsics) {
  if (intrinsics.distortion.empty()) return normalisedRays(pixels, intrinsics);
  if (table_.empty() || !(intrinsics == intrinsics_)) {
    std::vector<cv::Point> every;
    every.reserve(static_cast<std::size_t>(intrinsics.width) *
                  static_cast<std::size_t>(intrinsics.height));
    for (int y = 0; y < intrinsics.height; ++y) {
      for (int x = 0; x < intrinsics.width; ++x)
        every.emplace_back(x, y);
    }
    table_.clear();  // a throw below leaves no table to read
    table_ = normalisedRays(every, intrinsics);
    intrinsics_ = intrinsics;
  }
  std::vector<cv::Point2f> out(pixels.size());
  for (std::size_t k = 0; k < pixels.size(); ++k) {
    const cv::Point& p = pixels[k];
    out[k] = table_[static_cast<std::size_t>(p.y) * static_cast<std::size_t>(intrinsics.width) +
                    static_cast<std::size_t>(p.x)];
  }
  return out;
}

}  // namespace cvo
