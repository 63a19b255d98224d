// A small binary file for labeled clouds ("CVOCLOUD 1", then point count, colour flag and
// semantic class count, then the float arrays): real clouds exported once from the front end so
// that core tests and benchmarks run without OpenCV.
#pragma once

#include <string>

#include "cvo_odometry/core/labeled_cloud.hpp"

namespace cvo {

void writeCloud(const std::string& path, const LabeledCloud& cloud);
// Throws FormatError for a truncated or foreign file.
LabeledCloud readCloud(const std::string& path);

}  // namespace cvo
