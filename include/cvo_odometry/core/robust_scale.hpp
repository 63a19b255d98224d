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

// medianInPlace's value, found faster when `guess` lies near it (an iterative solver's last
// scale; without one, a large set's guess is the median of every 16th value): only the values
// within 10 % of the guess are ordered, the whole set when the median is not among them. Exact
// either way. `values` may be reordered; `scratch` is reused storage.
inline double medianNear(std::vector<double>& values, double guess, std::vector<double>& scratch) {
  constexpr std::size_t kSampleStride = 16;
  const std::size_t k = values.size() / 2;
  if (!(guess > 0.0) && values.size() >= 64 * kSampleStride) {
    scratch.clear();
    for (std::size_t i = 0; i < values.size(); i += kSampleStride)
      scratch.push_back(values[i]);
    guess = medianInPlace(scratch);
  }
  if (guess > 0.0 && std::isfinite(guess)) {
    const double low = 0.9 * guess, high = 1.1 * guess;
    scratch.resize(values.size());
    std::size_t below = 0, inside = 0;
    // Branchless: which side a value falls on is a coin toss near the median.
    for (const double v : values) {
      below += v < low ? 1 : 0;
      scratch[inside] = v;
      inside += v >= low && v <= high ? 1 : 0;
    }
    if (below <= k && k < below + inside) {
      const auto middle = scratch.begin() + static_cast<std::ptrdiff_t>(k - below);
      std::nth_element(scratch.begin(), middle,
                       scratch.begin() + static_cast<std::ptrdiff_t>(inside));
      return *middle;
    }
  }
  return medianInPlace(values);
}

// Huber's weight of a residual of size `magnitude` at threshold `huber`.
inline double huberWeight(double magnitude, double huber) {
  return magnitude <= huber ? 1.0 : huber / magnitude;
}

}  // namespace cvo
