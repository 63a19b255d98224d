// Which pixels become cloud points. FAST corners (OpenCV, no non-max suppression) with a
// threshold adapted frame to frame so that the count of selected pixels with valid depth lands
// in [min_points, max_points]; a uniform grid; or half of each (mixed).
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "cvo_odometry/core/settings_table.hpp"

namespace cvo {

// kMixed: half the points FAST corners, half a uniform grid.
enum class SelectorKind { kFast, kGrid, kMixed };

struct SelectorOptions {
  SelectorKind kind = SelectorKind::kGrid;
  int min_points = 3000;
  int max_points = 15000;
  int initial_fast_threshold = 9;
  int max_fast_attempts = 12;
};

struct SelectionStats {
  std::size_t candidates = 0;  // selected pixels with valid depth before capping
  std::size_t selected = 0;
  int fast_threshold = 0;  // threshold used (FAST only)
  double time_ms = 0.0;
};

class PointSelector {
 public:
  explicit PointSelector(const SelectorOptions& options);

  // `grey`: 8-bit image; `valid`: 8-bit mask, non-zero where depth is usable. Returns pixel
  // coordinates in row-major order; at most max_points (evenly thinned when above).
  std::vector<cv::Point> select(const cv::Mat& grey, const cv::Mat& valid, SelectionStats* stats);

  const SelectorOptions& options() const { return options_; }

 private:
  std::vector<cv::Point> fastPixels(const cv::Mat& grey, const cv::Mat& valid, int threshold) const;
  std::vector<cv::Point> gridPixels(const cv::Mat& valid, double target) const;
  std::vector<cv::Point> adaptiveFastPixels(const cv::Mat& grey, const cv::Mat& valid,
                                            std::size_t lo, std::size_t hi, int* used_threshold);

  SelectorOptions options_;
  int threshold_;  // carried to the next frame: consecutive frames need similar thresholds
};

const std::vector<EnumName<SelectorKind>>& enumNames(SelectorKind);
SelectorKind parseSelectorKind(const std::string& name);

}  // namespace cvo
