#include "cvo_odometry/frontend/point_selector.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <opencv2/features2d.hpp>

namespace cvo {

namespace {

std::vector<cv::Point> thinEvenly(std::vector<cv::Point> pixels, std::size_t count) {
  if (pixels.size() <= count) return pixels;
  std::vector<cv::Point> out;
  out.reserve(count);
  const double stride = static_cast<double>(pixels.size()) / count;
  for (std::size_t k = 0; k < count; ++k)
    out.push_back(pixels[static_cast<std::size_t>(k * stride)]);
  return out;
}

bool rowMajor(const cv::Point& a, const cv::Point& b) {
  return a.y != b.y ? a.y < b.y : a.x < b.x;
}

}  // namespace

PointSelector::PointSelector(const SelectorOptions& options)
    : options_(options), threshold_(options.initial_fast_threshold) {
  if (options.min_points < 1 || options.max_points < options.min_points) {
    throw std::invalid_argument("point count range [" + std::to_string(options.min_points) + ", " +
                                std::to_string(options.max_points) + "] makes no sense");
  }
  if (options.initial_fast_threshold < 1 || options.initial_fast_threshold > 254) {
    throw std::invalid_argument("FAST threshold must be in [1, 254]");
  }
}

const std::vector<EnumName<SelectorKind>>& enumNames(SelectorKind) {
  static const std::vector<EnumName<SelectorKind>> names{{SelectorKind::kGrid, "grid"},
                                                         {SelectorKind::kFast, "fast"},
                                                         {SelectorKind::kMixed, "mixed"}};
  return names;
}

SelectorKind parseSelectorKind(const std::string& name) {
  return parseEnum<SelectorKind>("point_selector", name);
}

std::vector<cv::Point> PointSelector::fastPixels(const cv::Mat& grey, const cv::Mat& valid,
                                                 int threshold) const {
  std::vector<cv::KeyPoint> keypoints;
  cv::FAST(grey, keypoints, threshold, false);
  std::vector<cv::Point> pixels;
  pixels.reserve(keypoints.size());
  for (const auto& kp : keypoints) {
    const cv::Point p(static_cast<int>(kp.pt.x), static_cast<int>(kp.pt.y));
    if (valid.at<std::uint8_t>(p)) pixels.push_back(p);
  }
  std::sort(pixels.begin(), pixels.end(), rowMajor);
  return pixels;
}

std::vector<cv::Point> PointSelector::adaptiveFastPixels(const cv::Mat& grey, const cv::Mat& valid,
                                                         std::size_t lo, std::size_t hi,
                                                         int* used_threshold) {
  // Walk the threshold towards the range; keep the attempt whose count is nearest to it.
  std::vector<cv::Point> pixels;
  std::size_t best_distance = SIZE_MAX;
  int direction = 0;
  for (int attempt = 0; attempt < options_.max_fast_attempts; ++attempt) {
    auto candidate = fastPixels(grey, valid, threshold_);
    const std::size_t n = candidate.size();
    const std::size_t distance = n < lo ? lo - n : (n > hi ? n - hi : 0);
    if (distance < best_distance) {
      best_distance = distance;
      pixels = std::move(candidate);
      *used_threshold = threshold_;
    }
    if (distance == 0) break;
    const int step = n < lo ? -1 : 1;
    if (direction != 0 && step != direction) break;  // overshot the range: take the best
    direction = step;
    // Bigger strides far from the range: the count falls roughly geometrically in the threshold.
    const double ratio = n < lo ? static_cast<double>(lo) / std::max<std::size_t>(n, 1)
                                : static_cast<double>(n) / hi;
    const int stride = ratio > 2.0 ? 3 : 1;
    const int next = std::clamp(threshold_ + step * stride, 1, 254);
    if (next == threshold_) break;
    threshold_ = next;
  }
  threshold_ = *used_threshold;
  return pixels;
}

std::vector<cv::Point> PointSelector::gridPixels(const cv::Mat& valid, double target) const {
  const int valid_count = cv::countNonZero(valid);
  const int stride = std::max(1, static_cast<int>(std::floor(std::sqrt(valid_count / target))));
  std::vector<cv::Point> pixels;
  for (int v = stride / 2; v < valid.rows; v += stride) {
    const auto* row = valid.ptr<std::uint8_t>(v);
    for (int u = stride / 2; u < valid.cols; u += stride) {
      if (row[u]) pixels.emplace_back(u, v);
    }
  }
  return pixels;
}

std::vector<cv::Point> PointSelector::select(const cv::Mat& grey, const cv::Mat& valid,
                                             SelectionStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  if (grey.type() != CV_8UC1 || valid.type() != CV_8UC1 || grey.size() != valid.size()) {
    throw std::invalid_argument("point selection needs an 8-bit grey image and a mask of its size");
  }
  const std::size_t lo = static_cast<std::size_t>(options_.min_points);
  const std::size_t hi = static_cast<std::size_t>(options_.max_points);
  const double middle = 0.5 * static_cast<double>(lo + hi);
  std::vector<cv::Point> pixels;
  int used_threshold = 0;
  if (options_.kind == SelectorKind::kGrid) {
    pixels = gridPixels(valid, middle);
  } else if (options_.kind == SelectorKind::kFast) {
    pixels = adaptiveFastPixels(grey, valid, lo, hi, &used_threshold);
  } else {
    // Half the budget on corners (appearance), half on a grid (geometry everywhere).
    pixels = adaptiveFastPixels(grey, valid, lo / 2, hi / 2, &used_threshold);
    const auto grid = gridPixels(valid, middle / 2);
    pixels.insert(pixels.end(), grid.begin(), grid.end());
    std::sort(pixels.begin(), pixels.end(), rowMajor);
    pixels.erase(std::unique(pixels.begin(), pixels.end()), pixels.end());
  }
  if (stats) {
    stats->candidates = pixels.size();
    stats->fast_threshold = used_threshold;
  }
  pixels = thinEvenly(std::move(pixels), static_cast<std::size_t>(options_.max_points));
  if (stats) {
    stats->selected = pixels.size();
    stats->time_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  return pixels;
}

}  // namespace cvo
