#include "cvo_odometry/frontend/semantic_image.hpp"

#include <algorithm>
#include <cstdint>
#include <stdexcept>

#include <opencv2/core.hpp>

namespace cvo {

SemanticImage::SemanticImage(const cv::Mat& image, int classes, const std::vector<int>& ignore)
    : image_(image), classes_(classes), ignore_(ignore) {
  if (image.empty()) throw std::invalid_argument("segmentation image is empty");
  if (classes < 1) throw std::invalid_argument("segmentation needs at least one class");
  const bool ids = image.channels() == 1 && (image.depth() == CV_8U || image.depth() == CV_16U);
  const bool probs = image.depth() == CV_32F && image.channels() == classes;
  if (!ids && !probs) {
    throw std::invalid_argument(
        "unsupported segmentation image (type " + std::to_string(image.type()) + ", " +
        std::to_string(image.channels()) + " channels): expected 8/16-bit class ids or " +
        std::to_string(classes) + " float channels");
  }
}

bool SemanticImage::ignored(int cls) const {
  return std::find(ignore_.begin(), ignore_.end(), cls) != ignore_.end();
}

cv::Mat SemanticImage::excludedMask() const {
  cv::Mat mask(image_.size(), CV_8UC1);
  if (image_.depth() == CV_8U) {
    cv::Mat table(1, 256, CV_8UC1);
    for (int id = 0; id < 256; ++id)
      table.at<std::uint8_t>(id) = id >= classes_ || ignored(id) ? 255 : 0;
    cv::LUT(image_, table, mask);
    return mask;
  }
  for (int v = 0; v < image_.rows; ++v) {
    std::uint8_t* out = mask.ptr<std::uint8_t>(v);
    for (int u = 0; u < image_.cols; ++u) {
      int cls;
      if (image_.depth() == CV_32F) {
        const float* p = image_.ptr<float>(v) + static_cast<std::size_t>(classes_) * u;
        cls = static_cast<int>(std::max_element(p, p + classes_) - p);
      } else {
        cls = image_.at<std::uint16_t>(v, u);
      }
      out[u] = cls >= classes_ || ignored(cls) ? 255 : 0;
    }
  }
  return mask;
}

bool SemanticImage::probabilities(int u, int v, float* out) const {
  if (image_.depth() == CV_32F) {
    const float* p = image_.ptr<float>(v) + static_cast<std::size_t>(classes_) * u;
    const int best = static_cast<int>(std::max_element(p, p + classes_) - p);
    if (ignored(best)) return false;
    std::copy(p, p + classes_, out);
    return true;
  }
  const int cls =
      image_.depth() == CV_8U ? image_.at<std::uint8_t>(v, u) : image_.at<std::uint16_t>(v, u);
  if (cls >= classes_ || ignored(cls)) return false;
  std::fill(out, out + classes_, 0.0f);
  out[cls] = 1.0f;
  return true;
}

}  // namespace cvo
