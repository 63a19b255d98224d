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

namespace {

// Bilinear interpolation of a 2x2 block of values (top-left, top-right, bottom-left,
// bottom-right): a weighs the right column, b the bottom row.
double interpolate(float top_left, float top_right, float bottom_left, float bottom_right, double a,
                   double b) {
  return (1.0 - b) * ((1.0 - a) * top_left + a * top_right) +
         b * ((1.0 - a) * bottom_left + a * bottom_right);
}

}  // namespace

double IntensityImage::intensity(int level, double u, double v) const {
  const float* I = levels_[level].values.data();
  const int u0 = static_cast<int>(u), v0 = static_cast<int>(v);
  const std::size_t i = static_cast<std::size_t>(v0) * width_ + u0;
  return interpolate(I[i], I[i + 1], I[i + width_], I[i + width_ + 1], u - u0, v - v0);
}

IntensitySample IntensityImage::sample(int level, double u, double v) const {
  const float* I = levels_[level].values.data();
  const int u0 = static_cast<int>(u), v0 = static_cast<int>(v);
  const auto w = static_cast<std::size_t>(width_);
  const std::size_t i = static_cast<std::size_t>(v0) * w + u0;
  // inside() keeps (u0, v0) off the outermost rows and columns; the 2x2's right column or bottom
  // row can be on them, where the gradient is zero.
  const bool right_border = u0 + 2 == width_, bottom_border = v0 + 2 == height_;
  const auto gradients = [&](std::size_t k, bool border, float* gu, float* gv) {
    *gu = border ? 0.0f : 0.5f * (I[k + 1] - I[k - 1]);
    *gv = border ? 0.0f : 0.5f * (I[k + w] - I[k - w]);
  };
  float gu[4], gv[4];
  gradients(i, false, &gu[0], &gv[0]);
  gradients(i + 1, right_border, &gu[1], &gv[1]);
  gradients(i + w, bottom_border, &gu[2], &gv[2]);
  gradients(i + w + 1, right_border || bottom_border, &gu[3], &gv[3]);
  const double a = u - u0, b = v - v0;
  return {interpolate(I[i], I[i + 1], I[i + w], I[i + w + 1], a, b),
          interpolate(gu[0], gu[1], gu[2], gu[3], a, b),
          interpolate(gv[0], gv[1], gv[2], gv[3], a, b)};
}

}  // namespace cvo
