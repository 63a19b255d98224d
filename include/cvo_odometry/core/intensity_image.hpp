// A grey camera image for the photometric rotation stage: one or more levels of the same image
// blurred by decreasing amounts (coarse first), and the camera model that projects points into
// it. Gradients are central differences taken where a sample needs them: stored gradient images
// tripled the memory of every kept frame (11 MB at 640x480 with three levels), and touching that
// much new memory made the first frames 2-3x slower than the rest. Built by the front end (which
// owns OpenCV); the core only samples it.
#pragma once

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
};

}  // namespace cvo
