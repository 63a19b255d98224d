// Robust statistics: the median (the upper one for an even count) that the image-based solvers
// (photometric stage, feature tracks), the tracks' agreement, the trajectory evaluation and the
// stamp pairer use, and the solvers' residual scale and Huber weights.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

namespace cvo {

constexpr double kHuberScale = 1.345;  // 95% efficiency under Gaussian residuals
constexpr double kMadToSigma = 1.4826;

// Median of `values` (partially sorts them); `values` must not be empty.
inline double medianInPlace(std::vector<double>& values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// Huber's weight of a residual of size `magnitude` at threshold `huber`.
inline double huberWeight(double magnitude, double huber) {
  return magnitude <= huber ? 1.0 : huber / magnitude;
}

}  // namespace cvo
