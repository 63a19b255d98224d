#include "cvo_odometry/frontend/colour_class_labels.hpp"

#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace cvo {

namespace {

constexpr int kDarkBelow = 60;      // value (0-255)
constexpr int kBrightFrom = 170;    // value, unsaturated pixels
constexpr int kSaturatedFrom = 80;  // saturation (0-255)

std::uint8_t classOf(const cv::Vec3b& hsv) {
  const int hue = hsv[0], saturation = hsv[1], value = hsv[2];  // OpenCV hue: 0-179
  if (value < kDarkBelow) return 0;
  if (saturation < kSaturatedFrom) return value < kBrightFrom ? 1 : 2;
  // Sectors of 120 deg centred on red, green and blue.
  const int sector = ((hue + 30) % 180) / 60;
  return static_cast<std::uint8_t>(3 + sector);
}

}  // namespace

cv::Mat colourClassLabels(const cv::Mat& image) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3)) {
    throw std::invalid_argument("colourClassLabels: expected an 8-bit BGR or grey image");
  }
  cv::Mat bgr = image;
  if (image.channels() == 1) cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  cv::Mat hsv;
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
  cv::Mat labels(image.size(), CV_8UC1);
  for (int v = 0; v < hsv.rows; ++v) {
    const auto* in = hsv.ptr<cv::Vec3b>(v);
    auto* out = labels.ptr<std::uint8_t>(v);
    for (int u = 0; u < hsv.cols; ++u)
      out[u] = classOf(in[u]);
  }
  cv::medianBlur(labels, labels, 5);
  return labels;
}

}  // namespace cvo
