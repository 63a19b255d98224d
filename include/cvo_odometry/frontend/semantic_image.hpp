// Per-pixel class probabilities from a segmentation image: class ids (8- or 16-bit, one-hot) or
// N float channels of probabilities. Pixels of an ignored class (e.g. sky) are dropped.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace cvo {

class SemanticImage {
 public:
  // `classes` is the length of the probability vector; throws std::invalid_argument for an
  // unsupported image type or a channel count that does not match `classes`.
  SemanticImage(const cv::Mat& image, int classes, const std::vector<int>& ignore_classes = {});

  // Writes the probabilities of pixel (u, v) to `out` (classes floats); false if the pixel's
  // most likely class is ignored or its id is out of range.
  bool probabilities(int u, int v, float* out) const;
  // CV_8UC1, 255 where probabilities() is false (an ignored class, or an id out of range), else 0.
  cv::Mat excludedMask() const;
  int classes() const { return classes_; }
  cv::Size size() const { return image_.size(); }

 private:
  bool ignored(int cls) const;

  cv::Mat image_;
  int classes_;
  std::vector<int> ignore_;
};

}  // namespace cvo
