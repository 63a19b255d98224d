#include "cvo_odometry/core/intensity_image.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace cvo {

IntensityImage::IntensityImage(int width, int height, const CameraModel& camera,
                               std::vector<Level> levels, std::vector<std::uint8_t> excluded)
    : width_(width),
      height_(height),
      camera_(camera),
      levels_(std::move(levels)),
      excluded_(std::move(excluded)) {
  if (width < 3 || height < 3) throw std::invalid_argument("intensity image smaller than 3x3");
  if (levels_.empty()) throw std::invalid_argument("intensity image without levels");
  const std::size_t size = static_cast<std::size_t>(width) * height;
  if (!excluded_.empty() && excluded_.size() != size) {
    throw std::invalid_argument("intensity image mask has " + std::to_string(excluded_.size()) +
                                " pixels for " + std::to_string(width) + "x" +
                                std::to_string(height));
  }
  for (const Level& level : levels_) {
    if (level.values.size() != size) {
      throw std::invalid_argument("intensity image level has " +
                                  std::to_string(level.values.size()) + " values for " +
                                  std::to_string(width) + "x" + std::to_string(height));
    }
  }
}

}  // namespace cvo
