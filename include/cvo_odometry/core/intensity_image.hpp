// A grey camera image for the photometric rotation stage: one or more levels of the same image
// blurred by decreasing amounts (coarse first), and the camera model that projects points into
// it. Gradients are central differences taken where a sample needs them: stored gradient images
// tripled the memory of every kept frame (11 MB at 640x480 with three levels), and touching that
// much new memory made the first frames 2-3x slower than the rest. Built by the front end (which
// owns OpenCV); the core only samples it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "cvo_odometry/core/camera_model.hpp"

namespace cvo {

struct IntensitySample {
  double intensity = 0.0, gradient_u = 0.0, gradient_v = 0.0;
};

class IntensityImage {
 public:
  struct Level {
    double blur_sigma = 0.0;    // pixels, of the Gaussian applied by whoever built it
    std::vector<float> values;  // row-major width x height, intensity in [0, 1]
  };

  // Throws std::invalid_argument for an empty size, no level, or a level of the wrong size.
  // `excluded` (row-major, non-zero where a pixel must not be used: a moving or ignored class)
  // is empty when every pixel may be used, else one byte a pixel.
  IntensityImage(int width, int height, const CameraModel& camera, std::vector<Level> levels,
                 std::vector<std::uint8_t> excluded = {});

  int width() const { return width_; }
  int height() const { return height_; }
  int levelCount() const { return static_cast<int>(levels_.size()); }
  double blurSigma(int level) const { return levels_[level].blur_sigma; }
  const CameraModel& camera() const { return camera_; }

  // True when (u, v) is far enough inside for bilinear sampling of the central differences.
  bool inside(double u, double v) const {
    return u >= 1.0 && v >= 1.0 && u <= width_ - 2.0 && v <= height_ - 2.0;
  }
  // False where the pixel nearest (u, v) is excluded; requires inside(u, v).
  bool usable(double u, double v) const {
    return excluded_.empty() || excluded_[static_cast<std::size_t>(v + 0.5) * width_ +
                                          static_cast<std::size_t>(u + 0.5)] == 0;
  }
  bool hasExcludedPixels() const { return !excluded_.empty(); }
  // Bilinear intensity and gradients (per pixel) at (u, v); requires inside(u, v). A border
  // pixel of the 2x2 (weight 0 within inside()) gets a zero gradient: no read beyond the image.
  // Inline: the photometric stage calls these once a point an iteration.
  IntensitySample sample(int level, double u, double v) const;
  // The bilinear intensity alone, as sample() gives it.
  double intensity(int level, double u, double v) const;

  // Moves the levels out, leaving the image without any: for a front end that reuses their
  // buffers once the image is done with (call it only then).
  std::vector<Level> releaseLevels() { return std::move(levels_); }

 private:
  int width_, height_;
  CameraModel camera_;
  std::vector<Level> levels_;
  std::vector<std::uint8_t> excluded_;

  // Bilinear interpolation of a 2x2 block of values (top-left, top-right, bottom-left,
  // bottom-right): a weighs the right column, b the bottom row.
  static double bilinear(float top_left, float top_right, float bottom_left, float bottom_right,
                         double a, double b);
};

inline double IntensityImage::bilinear(float top_left, float top_right, float bottom_left,
                                       float bottom_right, double a, double b) {
  return (1.0 - b) * ((1.0 - a) * top_left + a * top_right) +
         b * ((1.0 - a) * bottom_left + a * bottom_right);
}

inline double IntensityImage::intensity(int level, double u, double v) const {
  const float* I = levels_[level].values.data();
  const int u0 = static_cast<int>(u), v0 = static_cast<int>(v);
  const std::size_t i = static_cast<std::size_t>(v0) * width_ + u0;
  return bilinear(I[i], I[i + 1], I[i + width_], I[i + width_ + 1], u - u0, v - v0);
}

inline IntensitySample IntensityImage::sample(int level, double u, double v) const {
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
  return {bilinear(I[i], I[i + 1], I[i + w], I[i + w + 1], a, b),
          bilinear(gu[0], gu[1], gu[2], gu[3], a, b), bilinear(gv[0], gv[1], gv[2], gv[3], a, b)};
}

}  // namespace cvo
