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
  // Entries are filled as pixels are first asked for: no start-up cost for the whole image.
  std::vector<cv::Point> missing;
  for (const cv::Point& p : pixels) {
    const std::size_t i = static_cast<std::size_t>(p.y) * width + static_cast<std::size_t>(p.x);
    if (std::isnan(table_[i].x)) missing.push_back(p);
  }
  const std::vector<cv::Point2f> found = normalisedRays(missing, intrinsics);
  for (std::size_t k = 0; k < missing.size(); ++k)
    table_[static_cast<std::size_t>(missing[k].y) * width +
           static_cast<std::size_t>(missing[k].x)] = found[k];
  std::vector<cv::Point2f> out(pixels.size());
  for (std::size_t k = 0; k < pixels.size(); ++k)
    out[k] = table_[static_cast<std::size_t>(pixels[k].y) * width +
                    static_cast<std::size_t>(pixels[k].x)];
  return out;
}

}  // namespace cvo
