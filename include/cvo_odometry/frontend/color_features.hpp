#pragma once

#include <opencv2/core.hpp>

namespace cvo {

// The 5-D colour feature image of the CVO notes (CV_32FC(5)): B, G, R in [0, 1] and the image
// gradients gx / 500 + 0.5, gy / 500 + 0.5 (central differences on the 0-255 grey image).
// Accepts 8-bit BGR (3 channels) or grey (1 channel: B = G = R); throws std::invalid_argument
// for anything else.
cv::Mat colorFeatures(const cv::Mat& image);
// The same 5 values at pixel (u, v) alone, into `out`; `grey` is toGrey(image). Cheaper than the
// whole image when only the selected points need them.
void colorFeaturesAt(const cv::Mat& image, const cv::Mat& grey, int u, int v, float* out);

// 8-bit grey version of an 8-bit BGR or grey image.
cv::Mat toGrey(const cv::Mat& image);

}  // namespace cvo
