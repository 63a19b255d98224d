#include "cvo_odometry/core/intensity_image.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace cvo {

IntensityImage::IntensityImage(int width, int height, const CameraModel& camera,
                               std::vector<Level> levels)
    : width_(width), height_(height), camera_(camera), levels_(std::move(levels)) {
  if (width < 3 || height < 3) throw std::invalid_argument("intensity image smaller than 3x3");
  if (levels_.empty()) throw std::invalid_argument("intensity image without levels");
  const std::size_t size = static_cast<std::size_t>(width) * height;
  for (const Level& level : levels_) {
    if (level.values.size() != size) {
      throw std::invalid_argument("intensity image level has " +
                                  std::to_string(level.values.size()) + " values for " +
                                  std::to_string(width) + "x" + std::to_string(height));
    }
  }
  for (const Level& level : levels_) {
    std::vector<float> gu(size, 0.0f), gv(size, 0.0f);
    const float* I = level.values.data();
    for (int v = 1; v + 1 < height; ++v) {
      for (int u = 1; u + 1 < width; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * width + u;
        gu[i] = 0.5f * (I[i + 1] - I[i - 1]);
        gv[i] = 0.5f * (I[i + width] - I[i - width]);
      }
    }
    gradient_u_.push_back(std::move(gu));
    gradient_v_.push_back(std::move(gv));
  }
}

IntensitySample IntensityImage::sample(int level, double u, double v) const {
  const int u0 = static_cast<int>(u), v0 = static_cast<int>(v);
  const double a = u - u0, b = v - v0;
  const std::size_t i = static_cast<std::size_t>(v0) * width_ + u0;
  auto bilinear = [&](const std::vector<float>& m) {
    return (1.0 - b) * ((1.0 - a) * m[i] + a * m[i + 1]) +
           b * ((1.0 - a) * m[i + width_] + a * m[i + width_ + 1]);
  };
  return {bilinear(levels_[level].values), bilinear(gradient_u_[level]),
          bilinear(gradient_v_[level])};
}

}  // namespace cvo
