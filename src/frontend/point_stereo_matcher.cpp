#include "cvo_odometry/frontend/point_stereo_matcher.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <functional>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "cvo_odometry/frontend/block_costs.hpp"
#include "cvo_odometry/frontend/color_features.hpp"
#include "cvo_odometry/frontend/stereo_matcher.hpp"

namespace cvo {

namespace {

// Bytes blockCosts reads beyond a window row at most (twice that: blockCostsInLanes).
constexpr int kReadBeyond = 16;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

int roundUp(int n, int multiple) {
  return (n + multiple - 1) / multiple * multiple;
}

// SGBM's prefilter (OpenCV's prefilterXSobel): the 3x3 Sobel x-derivative clipped to
// [-cap, cap] and shifted by cap, rows [row0, rows) of `grey` (rows beyond the image repeat the
// edge ones), into `out` padded by `pad` columns of cap (no derivative) on either side.
void prefilter(const cv::Mat& grey, int row0, int cap, int pad, cv::Mat* out) {
  const int rows = grey.rows, cols = grey.cols;
  out->create(rows - row0, cols + 2 * pad, CV_8UC1);
  out->setTo(cap);
  for (int y = row0; y < rows; ++y) {
    const std::uint8_t* above = grey.ptr<std::uint8_t>(std::max(y - 1, 0));
    const std::uint8_t* middle = grey.ptr<std::uint8_t>(y);
    const std::uint8_t* below = grey.ptr<std::uint8_t>(std::min(y + 1, rows - 1));
    std::uint8_t* o = out->ptr<std::uint8_t>(y - row0) + pad;
    for (int x = 1; x + 1 < cols; ++x) {
      const int d = 2 * (middle[x + 1] - middle[x - 1]) + above[x + 1] - above[x - 1] +
                    below[x + 1] - below[x - 1];
      o[x] = static_cast<std::uint8_t>(std::clamp(d, -cap, cap) + cap);
    }
  }
}

}  // namespace

void PointMatcherOptions::validate() const {
  StereoMatcherOptions sgbm;
  sgbm.min_disparity = min_disparity;
  sgbm.num_disparities = num_disparities;
  sgbm.block_size = block_size;
  sgbm.validate();  // the same rules as the dense matcher's
  if (refine_width != 0 && (refine_width < 3 || refine_width % 2 == 0 || refine_width > 15)) {
    throw std::invalid_argument(
        "refine_width must be 0 (the search window) or odd in [3, 15], got " +
        std::to_string(refine_width));
  }
  if (refine_width != 0 && (refine_height < 1 || refine_height % 2 == 0 || refine_height > 21)) {
    throw std::invalid_argument("refine_height must be odd and in [1, 21], got " +
                                std::to_string(refine_height));
  }
  if (coarse_level < 0 || coarse_level > 3) {
    throw std::invalid_argument("coarse_level must be 0 (no coarse disparity) to 3, got " +
                                std::to_string(coarse_level));
  }
  if (search_radius < 1 || search_radius > 32) {
    throw std::invalid_argument("search_radius must be in [1, 32] px, got " +
                                std::to_string(search_radius));
  }
  // 16-bit costs: the window's area times the largest difference, 2 * cap, must fit.
  if (prefilter_cap < 1 || prefilter_cap > 63) {
    throw std::invalid_argument("prefilter_cap must be in [1, 63], got " +
                                std::to_string(prefilter_cap));
  }
  if (uniqueness_ratio < 0 || uniqueness_ratio > 99) {
    throw std::invalid_argument("uniqueness_ratio must be in [0, 99], got " +
                                std::to_string(uniqueness_ratio));
  }
  if (max_lr_difference < 0) {
    throw std::invalid_argument("max_lr_difference must be >= 0, got " +
                                std::to_string(max_lr_difference));
  }
}

PointStereoMatcher::PointStereoMatcher(const PointMatcherOptions& options) : options_(options) {
  options_.validate();
  if (options_.coarse_level > 0) {
    const int scale = 1 << options_.coarse_level;
    // The coarse range covers the full one; a 5-pixel block at 1/2, 3 pixels below (the
    // coarse image's pixels already average 4 or 16 of the full image's).
    const int low = static_cast<int>(std::floor(options_.min_disparity / double(scale)));
    const int high = static_cast<int>(
        std::ceil((options_.min_disparity + options_.num_disparities) / double(scale)));
    const int block = options_.coarse_level == 1 ? 5 : 3;
    const int area = block * block;
    coarse_sgbm_ = cv::StereoSGBM::create(
        low, std::max(16, roundUp(high - low, 16)), block, 8 * area, 32 * area, 1, 63, 10,
        std::max(100 >> (2 * options_.coarse_level), 4), 2, cv::StereoSGBM::MODE_SGBM_3WAY);
  }
}

void PointStereoMatcher::prepare(const cv::Mat& left, const cv::Mat& right, int first_row,
                                 const std::function<void()>& beside) {
  checkStereoPair(left, right);
  if (left.type() != right.type()) {
    throw std::invalid_argument("left and right images are of different types");
  }
  if (first_row < 0 || first_row >= left.rows) {
    throw std::invalid_argument("first row " + std::to_string(first_row) + " is outside the " +
                                std::to_string(left.rows) + "-row image");
  }
  const cv::Mat grey_left = toGrey(left), grey_right = toGrey(right);  // throw on other types
  const int h = options_.block_size / 2;
  size_ = left.size();
  first_row_ = first_row;
  row0_ = std::max(0, first_row - std::max(h, options_.refine_height / 2));
  pad_ = std::abs(options_.min_disparity) + options_.num_disparities + 2 * kReadBeyond + h;
  coarse_.release();
  // Three independent parts, spread over OpenCV's threads (the coarse SGBM, the longest, first;
  // inside this loop it runs on one thread).
  const auto coarse = [&] {
    if (!coarse_sgbm_) return;
    const double scale = 1.0 / (1 << options_.coarse_level);
    const cv::Range band(first_row, size_.height);
    cv::Mat small_left, small_right;
    cv::resize(grey_left.rowRange(band), small_left, cv::Size(), scale, scale, cv::INTER_AREA);
    cv::resize(grey_right.rowRange(band), small_right, cv::Size(), scale, scale, cv::INTER_AREA);
    // A pair too small for the coarse SGBM (StereoMatcherOptions' width rule at its range) is
    // searched over the whole range at each pixel.
    StereoMatcherOptions rule;
    rule.min_disparity = coarse_sgbm_->getMinDisparity();
    rule.num_disparities = coarse_sgbm_->getNumDisparities();
    rule.block_size = coarse_sgbm_->getBlockSize();
    if (small_left.cols < rule.minImageWidth() || small_left.rows < 2) return;
    coarse_sgbm_->compute(small_left, small_right, coarse_);
  };
  const auto derivatives = [&] {
    prefilter(grey_left, row0_, options_.prefilter_cap, pad_, &left_);
    prefilter(grey_right, row0_, options_.prefilter_cap, pad_, &right_);
  };
  std::exception_ptr failure;
  cv::parallel_for_(
      cv::Range(0, beside ? 3 : 2),
      [&](const cv::Range& parts) {
        for (int part = parts.start; part < parts.end; ++part) {
          try {
            if (part == 0) coarse();
            if (part == 1) derivatives();
            if (part == 2) beside();
          } catch (...) {
            // Kept for the caller's thread (OpenCV would wrap it); the first one wins.
            static std::mutex mutex;
            std::lock_guard<std::mutex> lock(mutex);
            if (!failure) failure = std::current_exception();
          }
        }
      },
      beside ? 3 : 2);
  if (failure) {
    left_.release();
    right_.release();
    std::rethrow_exception(failure);
  }
}

bool PointStereoMatcher::searchInterval(int x, int y, int* lo, int* hi) const {
  const int h = options_.block_size / 2;
  // Disparities whose window lies inside the right image, one beyond either end of the
  // interval kept for the parabola.
  const int fits_lo = std::max(options_.min_disparity, x + h - (size_.width - 1)) + 1;
  const int fits_hi = std::min(options_.min_disparity + options_.num_disparities - 1, x - h) - 1;
  int from = fits_lo, to = fits_hi;
  if (!coarse_.empty()) {
    const int level = options_.coarse_level;
    const int cx = std::min(x >> level, coarse_.cols - 1);
    const int cy = std::min((y - first_row_) >> level, coarse_.rows - 1);
    if (cy < 0) return false;
    const int invalid_below = coarse_sgbm_->getMinDisparity() * 16;
    int low = std::numeric_limits<int>::max(), high = std::numeric_limits<int>::min();
    for (int v = std::max(cy - 1, 0); v <= std::min(cy + 1, coarse_.rows - 1); ++v) {
      const std::int16_t* row = coarse_.ptr<std::int16_t>(v);
      for (int u = std::max(cx - 1, 0); u <= std::min(cx + 1, coarse_.cols - 1); ++u) {
        if (row[u] < invalid_below) continue;
        low = std::min<int>(low, row[u]);
        high = std::max<int>(high, row[u]);
      }
    }
    if (low > high) return false;  // no coarse disparity around the pixel
    // Fixed point x16 at 1/2^level: (d << level) / 16 px at full resolution. (Widening it to
    // 16 disparities lost pixels to the uniqueness test: KITTI 06, stereo_point_precision,
    // 0.770 -> 0.750 of the tracks with a disparity.)
    from = std::max(from, ((low << level) >> 4) - options_.search_radius);
    to = std::min(to, (((high << level) + 15) >> 4) + options_.search_radius);
  }
  *lo = from;
  *hi = to;
  return from + 2 <= to;  // a best disparity with a cost on either side
}

float PointStereoMatcher::match(cv::Point pixel) const {
  return match(std::vector<cv::Point>{pixel}).front();
}

std::vector<float> PointStereoMatcher::match(const std::vector<cv::Point>& pixels) const {
  if (!prepared()) throw std::logic_error("PointStereoMatcher::match before prepare()");
  for (const cv::Point& p : pixels) {
    if (p.x < 0 || p.y < 0 || p.x >= size_.width || p.y >= size_.height) {
      throw std::invalid_argument("pixel (" + std::to_string(p.x) + ", " + std::to_string(p.y) +
                                  ") is outside the " + std::to_string(size_.width) + "x" +
                                  std::to_string(size_.height) + " image");
    }
  }
  std::vector<float> out(pixels.size(), kNaN);
  const auto body = [&](const cv::Range& range) {
    // The costs of disparities lo - 1 .. hi + 1 and those of the match back.
    std::vector<std::uint16_t> costs(static_cast<std::size_t>(2 * (options_.num_disparities + 2)));
    for (int k = range.start; k < range.end; ++k)
      out[static_cast<std::size_t>(k)] = matchOne(pixels[k].x, pixels[k].y, costs);
  };
  const int n = static_cast<int>(pixels.size());
  if (n < 256) {
    body(cv::Range(0, n));
  } else {
    cv::parallel_for_(cv::Range(0, n), body,
                      std::max(1, std::min(n / 256, 4 * cv::getNumThreads())));
  }
  return out;
}

float PointStereoMatcher::matchOne(int x, int y, std::vector<std::uint16_t>& costs) const {
  const int h = options_.block_size / 2;
  if (y < first_row_ || y - h < 0 || y + h >= size_.height || x - h < 0 || x + h >= size_.width) {
    return kNaN;
  }
  int lo = 0, hi = 0;
  if (!searchInterval(x, y, &lo, &hi)) return kNaN;
  const int side = 2 * h + 1;
  const std::uint8_t* left_rows[32];
  const std::uint8_t* right_rows[32];
  for (int r = 0; r < side; ++r) {
    left_rows[r] = left_.ptr<std::uint8_t>(y - h + r - row0_) + pad_;
    right_rows[r] = right_.ptr<std::uint8_t>(y - h + r - row0_) + pad_;
  }
  // Left to right: cost[i] is disparity hi + 1 - i's (the right image's pixels x - hi - 1 + i,
  // in increasing order), for disparities lo - 1 .. hi + 1.
  const int top = hi + 1;
  const std::uint8_t* a[32];
  const std::uint8_t* b[32];
  for (int r = 0; r < side; ++r) {
    a[r] = left_rows[r] + x;
    b[r] = right_rows[r] + x - top;
  }
  std::uint16_t* cost = costs.data();
  blockCosts(a, b, h, side, 0, hi - lo + 3, cost);
  const auto at = [&](int d) { return static_cast<int>(cost[top - d]); };
  int best = lo;
  for (int d = lo + 1; d <= hi; ++d) {
    if (at(d) < at(best)) best = d;
  }
  // At the interval's end the minimum may lie beyond it.
  if (best == lo || best == hi) return kNaN;
  const int best_cost = at(best);
  const int unique = 100 - options_.uniqueness_ratio;
  for (int d = lo; d <= hi; ++d) {
    if (std::abs(d - best) > 1 && at(d) * unique < best_cost * 100) return kNaN;
  }
  // Right to left: the right pixel x - best against the left pixels x - best + d, back[i] for
  // disparity lo + i.
  const int xr = x - best;
  for (int r = 0; r < side; ++r) {
    a[r] = right_rows[r] + xr;
    b[r] = left_rows[r] + xr + lo;
  }
  std::uint16_t* back = costs.data() + (hi - lo + 3);
  blockCosts(a, b, h, side, 0, hi - lo + 1, back);
  int back_best = lo;
  for (int d = lo + 1; d <= hi; ++d) {
    if (xr + d + h >= size_.width) break;  // the left window leaves the image
    if (back[d - lo] < back[back_best - lo]) back_best = d;
  }
  if (std::abs(back_best - best) > options_.max_lr_difference) return kNaN;
  return refine(x, y, best, lo, hi, cost, top);
}

float PointStereoMatcher::refine(int x, int y, int best, int lo, int hi, const std::uint16_t* costs,
                                 int top) const {
  const auto parabola = [](double minus, double centre, double plus, int at) {
    const double curvature = minus + plus - 2.0 * centre;
    const double offset = curvature > 0.0 ? (minus - plus) / (2.0 * curvature) : 0.0;
    return static_cast<float>(at + offset);
  };
  const int w = options_.refine_width / 2, hr = options_.refine_height / 2;
  // The search window's costs where the wider one leaves the prepared rows or either image.
  if (options_.refine_width == 0 || y - hr < row0_ || y + hr >= size_.height || x - w < 0 ||
      x + w >= size_.width || x - w - (best + 2) < 0) {
    return parabola(costs[top - best + 1], costs[top - best], costs[top - best - 1], best);
  }
  const int rows = 2 * hr + 1;
  const std::uint8_t* a[32];
  const std::uint8_t* b[32];
  // Costs of disparities best - 2 .. best + 2 (those in the searched interval and beside it):
  // wide[d - best + 2] for d in [first, last].
  const int first = std::max(best - 2, lo - 1), last = std::min(best + 2, hi + 1);
  for (int r = 0; r < rows; ++r) {
    a[r] = left_.ptr<std::uint8_t>(y - hr + r - row0_) + pad_ + x;
    b[r] = right_.ptr<std::uint8_t>(y - hr + r - row0_) + pad_ + x - last;
  }
  std::uint16_t by_shift[5];  // by_shift[i]: disparity last - i
  blockCosts(a, b, w, rows, 0, last - first + 1, by_shift);
  int wide[5];
  for (int d = first; d <= last; ++d)
    wide[d - best + 2] = by_shift[last - d];
  int centre = best;
  for (int d : {best - 1, best + 1}) {
    if (d - 1 >= first && d + 1 <= last && wide[d - best + 2] < wide[centre - best + 2]) centre = d;
  }
  const int minus = wide[centre - 1 - best + 2], middle = wide[centre - best + 2],
            plus = wide[centre + 1 - best + 2];
  if (minus < middle || plus < middle) return kNaN;  // the windows disagree on the minimum
  return parabola(minus, middle, plus, centre);
}

}  // namespace cvo
