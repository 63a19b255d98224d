#include "cvo_odometry/frontend/pinhole_intrinsics.hpp"

#include <cmath>
#include <stdexcept>

namespace cvo {

void PinholeIntrinsics::validate() const {
  auto fail = [](const std::string& what) {
    throw std::invalid_argument("invalid camera intrinsics: " + what);
  };
  if (width <= 0 || height <= 0) {
    fail("image size " + std::to_string(width) + "x" + std::to_string(height));
  }
  if (!std::isfinite(fx) || !std::isfinite(fy) || fx <= 0.0 || fy <= 0.0) {
    fail("focal lengths fx " + std::to_string(fx) + ", fy " + std::to_string(fy) +
         " must be positive and finite");
  }
  if (!std::isfinite(cx) || !std::isfinite(cy) || cx < -width || cx > 2.0 * width || cy < -height ||
      cy > 2.0 * height) {
    fail("principal point (" + std::to_string(cx) + ", " + std::to_string(cy) +
         ") is far outside the " + std::to_string(width) + "x" + std::to_string(height) + " image");
  }
  // The coefficient counts OpenCV's distortion models have (plumb_bob 5, rational 8, ...).
  const std::size_t n = distortion.size();
  if (n != 0 && n != 4 && n != 5 && n != 8 && n != 12 && n != 14) {
    fail(std::to_string(n) + " distortion coefficients (expected 0, 4, 5, 8, 12 or 14)");
  }
  for (double d : distortion) {
    if (!std::isfinite(d)) fail("a distortion coefficient is not finite");
  }
}

}  // namespace cvo
