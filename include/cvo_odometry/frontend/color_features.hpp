#pragma once

#include <opencv2/core.hpp>

namespace cvo {

// The 5-D colour feature of the CVO notes at pixel (u, v), into `out`: B, G, R in [0, 1] and the
// image gradients gx / 500 + 0.5, gy / 500 + 0.5 (central differences on the 0-255 grey image,
// the border replicated). `image`: 8-bit BGR (3 channels) or grey (1 channel: B = G = R);
// `grey` is toGrey(image), which refuses anything else.
void colorFeaturesAt(const cv::Mat& image, const cv::Mat& grey, int u, int v, float* out);

// 8-bit grey version of an 8-bit BGR or grey image; throws std::invalid_argument for anything
// else.
cv::Mat toGrey(const cv::Mat& image);

}  // namespace cvo
