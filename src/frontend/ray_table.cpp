#include "cvo_odometry/frontend/ray_table.hpp"

#include <cmath>
#include <limits>

#include "cvo_odometry/frontend/depth_cloud_builder.hpp"

namespace cvo {

std::vector<cv::Point2f> RayTable::rays(const std::vector<cv::Point>& pixels,
                                        const PinholeIntrinsics& intrinsics) {
  if (intrinsics.distortion.empty()) return normalisedRays(pixels, intrinsics);
  const auto width = static_cast<std::size_t>(intrinsics.width);
  if (table_.empty() || !(intrinsics == intrinsics_)) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    table_.clear();  // a throw below leaves no table, never one sized for other intrinsics
    intrinsics_ = intrinsics;
    table_.assign(width * static_cast<std::size_t>(intrinsics.height), cv::Point2f(nan, nan));
  }
  const auto slot = [width](const cv::Point& p) {
    return static_cast<std::size_t>(p.y) * width + static_cast<std::size_t>(p.x);
  };
  // Entries are filled as pixels are first asked for: no start-up cost for the whole image.
  std::vector<cv::Point> missing;
  for (const cv::Point& p : pixels) {
    if (std::isnan(table_[slot(p)].x)) missing.push_back(p);
  }
  const std::vector<cv::Point2f> found = normalisedRays(missing, intrinsics);
  for (std::size_t k = 0; k < missing.size(); ++k)
    table_[slot(missing[k])] = found[k];
  std::vector<cv::Point2f> out(pixels.size());
  for (std::size_t k = 0; k < pixels.size(); ++k)
    out[k] = table_[slot(pixels[k])];
  return out;
}

}  // namespace cvo
