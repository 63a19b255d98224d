// A segmentation without a learned model, for fixtures and demos: each pixel's class from its
// colour alone, the same rule in every frame, so a surface keeps its class while the camera moves
// (up to exposure changes at the class boundaries).
#pragma once

#include <opencv2/core.hpp>

namespace cvo {

// Classes: 0 dark, 1 grey, 2 bright (unsaturated), 3 red-yellow, 4 green-cyan, 5 blue-magenta
// (saturated, by hue). Grey images use classes 0-2 only.
constexpr int kColourClassCount = 6;

// 8-bit class ids (CV_8UC1) of an 8-bit BGR or grey image, median-filtered (5x5) so that
// texture does not speckle the classes. Throws std::invalid_argument for other images.
cv::Mat colourClassLabels(const cv::Mat& image);

}  // namespace cvo
