#include "cvo_odometry/frontend/color_features.hpp"

#include <algorithm>
#include <cstdint>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace cvo {

cv::Mat toGrey(const cv::Mat& image) {
  if (image.empty()) throw std::invalid_argument("image is empty");
  if (image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3)) {
    throw std::invalid_argument("unsupported image type " + std::to_string(image.type()) +
                                "; expected 8-bit BGR or 8-bit grey");
  }
  if (image.channels() == 1) return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

void colorFeaturesAt(const cv::Mat& image, const cv::Mat& grey, int u, int v, float* out) {
  const int rows = image.rows, cols = image.cols;
  const std::uint8_t* g = grey.ptr<std::uint8_t>(v);
  const std::uint8_t* px = image.ptr<std::uint8_t>(v);
  if (image.channels() == 3) {
    for (int k = 0; k < 3; ++k)
      out[k] = px[3 * u + k] / 255.0f;
  } else {
    out[0] = out[1] = out[2] = px[u] / 255.0f;
  }
  const int left = std::max(u - 1, 0), right = std::min(u + 1, cols - 1);
  const float gx = 0.5f * (static_cast<float>(g[right]) - g[left]);
  const float gy =
      0.5f * (static_cast<float>(grey.ptr<std::uint8_t>(std::min(v + 1, rows - 1))[u]) -
              grey.ptr<std::uint8_t>(std::max(v - 1, 0))[u]);
  out[3] = gx / 500.0f + 0.5f;
  out[4] = gy / 500.0f + 0.5f;
}

}  // namespace cvo
