#include "cvo_odometry/frontend/min_eigen_corners.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace cvo {

namespace {

// With spreading cells, a cell's corners need at least this fraction of the bar the image's
// strongest response sets (quality times it): a plain cell gives no corners of noise.
constexpr double kCellQualityFloor = 0.1;

// OpenCV's default border (BORDER_REFLECT_101): -1 -> 1, n -> n - 2.
int reflect(int i, int n) {
  return i < 0 ? -i : i >= n ? 2 * n - 2 - i : i;
}

// Raises most[x] to the response at (x, y) where the depth there is a number, for the rows
// [y0, y1). Responses are >= 0 and finite, so they order as their bits do: an integer maximum,
// element by element (it vectorises; a row's maximum, a reduction, stays scalar).
void raiseColumnMaxima(const cv::Mat& response, const cv::Mat& depth, int y0, int y1,
                       std::int32_t* __restrict most) {
  const int w = response.cols;
  for (int y = y0; y < y1; ++y) {
    const std::int32_t* __restrict r = response.ptr<std::int32_t>(y);
    const float* __restrict z = depth.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      const std::int32_t v = r[x] & -static_cast<std::int32_t>(z[x] == z[x]);
      most[x] = std::max(most[x], v);
    }
  }
}

}  // namespace

void MinEigenCorners::gradientProductRow(const cv::Mat& grey, int row, int slot) {
  const int w = grey.cols;
  const std::uint8_t* up = grey.ptr<std::uint8_t>(reflect(row - 1, grey.rows));
  const std::uint8_t* mid = grey.ptr<std::uint8_t>(row);
  const std::uint8_t* down = grey.ptr<std::uint8_t>(reflect(row + 1, grey.rows));
  // 3x3 Sobel, borders reflected: dx = s(x + 1) - s(x - 1), dy = d(x - 1) + 2 d(x) + d(x + 1)
  // with s and d the column's smoothing and difference (|dx|, |dy| <= 1020: 16 bits).
  std::int16_t* s = smooth_.data();
  std::int16_t* d = difference_.data();
  for (int x = 0; x < w; ++x) {
    s[x] = static_cast<std::int16_t>(up[x] + 2 * mid[x] + down[x]);
    d[x] = static_cast<std::int16_t>(down[x] - up[x]);
  }
  std::int16_t* dx = dx_.data();
  std::int16_t* dy = dy_.data();
  dx[0] = 0;
  dy[0] = static_cast<std::int16_t>(2 * (d[1] + d[0]));
  for (int x = 1; x + 1 < w; ++x) {
    dx[x] = static_cast<std::int16_t>(s[x + 1] - s[x - 1]);
    dy[x] = static_cast<std::int16_t>(d[x - 1] + 2 * d[x] + d[x + 1]);
  }
  dx[w - 1] = 0;
  dy[w - 1] = static_cast<std::int16_t>(2 * (d[w - 2] + d[w - 1]));
  // The products, exact in 32 bits even summed over 3x3 (<= 9 * 1020^2).
  std::int32_t* xx = product_xx_.data();
  std::int32_t* xy = product_xy_.data();
  std::int32_t* yy = product_yy_.data();
  for (int x = 0; x < w; ++x) {
    xx[x] = static_cast<std::int32_t>(dx[x]) * dx[x];
    xy[x] = static_cast<std::int32_t>(dx[x]) * dy[x];
    yy[x] = static_cast<std::int32_t>(dy[x]) * dy[x];
  }
  // Summed over x - 1 .. x + 1, borders reflected; one loop an array (they vectorise).
  const auto sum3 = [w](const std::int32_t* __restrict in, std::int32_t* __restrict out) {
    out[0] = 2 * in[1] + in[0];
    for (int x = 1; x + 1 < w; ++x)
      out[x] = in[x - 1] + in[x] + in[x + 1];
    out[w - 1] = 2 * in[w - 2] + in[w - 1];
  };
  const auto ring = static_cast<std::size_t>(slot) * w;
  sum3(xx, sum_xx_.data() + ring);
  sum3(xy, sum_xy_.data() + ring);
  sum3(yy, sum_yy_.data() + ring);
}

void MinEigenCorners::responseRow(int row, int above, int below) {
  const int w = response_.cols;
  const auto at = [w](const std::vector<std::int32_t>& sums, int slot) {
    return sums.data() + static_cast<std::size_t>(slot) * w;
  };
  const std::int32_t *xx0 = at(sum_xx_, above), *xx1 = at(sum_xx_, row % 3),
                     *xx2 = at(sum_xx_, below);
  const std::int32_t *xy0 = at(sum_xy_, above), *xy1 = at(sum_xy_, row % 3),
                     *xy2 = at(sum_xy_, below);
  const std::int32_t *yy0 = at(sum_yy_, above), *yy1 = at(sum_yy_, row % 3),
                     *yy2 = at(sum_yy_, below);
  float* out = response_.ptr<float>(row);
  for (int x = 0; x < w; ++x) {
    // The smaller eigenvalue of [a b; b c] as det / (the larger one): no cancellation at edges.
    // The sums are exact in float (< 2^24), the determinant in double (< 2^53). Branch-free
    // (and sqrt sets no errno: -fno-math-errno) so that the loop vectorises; 0 where flat.
    const std::int32_t a = xx0[x] + xx1[x] + xx2[x];
    const std::int32_t b = xy0[x] + xy1[x] + xy2[x];
    const std::int32_t c = yy0[x] + yy1[x] + yy2[x];
    const auto det = static_cast<float>(static_cast<double>(a) * c - static_cast<double>(b) * b);
    const auto fa = static_cast<float>(a), fb = static_cast<float>(b), fc = static_cast<float>(c);
    const float half_difference = 0.5f * (fa - fc);
    const float larger = 0.5f * (fa + fc) + std::sqrt(half_difference * half_difference + fb * fb);
    out[x] = det / std::max(larger, 1e-30f);
  }
}

const std::vector<cv::Point2f>& MinEigenCorners::find(const cv::Mat& grey, const cv::Mat& depth,
                                                      int first_row, int max_corners,
                                                      double quality, double min_distance,
                                                      int grid_columns) {
  if (grey.type() != CV_8UC1 || depth.type() != CV_32FC1 || depth.size() != grey.size()) {
    throw std::invalid_argument("corners: an 8-bit grey image and a float depth of its size");
  }
  if (!(quality > 0.0 && quality <= 1.0) || !(min_distance >= 0.0) ||
      !std::isfinite(min_distance)) {
    throw std::invalid_argument("corners: quality must be in (0, 1] and min_distance >= 0");
  }
  corners_.clear();
  const int w = grey.cols, h = grey.rows;
  first_row = std::max(first_row, 0);
  // A corner is a strict interior pixel: its 3x3 neighbourhood is compared.
  if (w < 3 || h < 3 || first_row > h - 2) return corners_;
  const int top = std::max(first_row - 1, 0);  // the first corners' neighbours above
  response_.create(h, w, CV_32FC1);
  for (auto* buffer : {&sum_xx_, &sum_xy_, &sum_yy_})
    buffer->resize(3 * static_cast<std::size_t>(w));
  for (auto* buffer : {&smooth_, &difference_, &dx_, &dy_})
    buffer->resize(static_cast<std::size_t>(w));
  for (auto* buffer : {&product_xx_, &product_xy_, &product_yy_})
    buffer->resize(static_cast<std::size_t>(w));
  // Row r's products live in ring slot r % 3; response row y reads rows y - 1 .. y + 1.
  const int first_products = std::max(top - 1, 0);
  for (int r = first_products; r <= top; ++r)
    gradientProductRow(grey, r, r % 3);
  for (int y = top; y < h; ++y) {
    if (y + 1 < h) gradientProductRow(grey, y + 1, (y + 1) % 3);
    responseRow(y, reflect(y - 1, h) % 3, reflect(y + 1, h) % 3);
  }

  // Spreading cells: square, grid_columns across the image, rows below first_row. Each cell's
  // corners are judged by its own strongest response (a high-contrast object elsewhere must not
  // lift the bar above a plainer background), but never below kCellQualityFloor of the image's.
  // Responses are >= 0 and finite: 0 stands for none.
  int bucket_side = 0, bucket_columns = 0, bucket_cap = 0;
  const bool spread = grid_columns > 0 && max_corners > 0;
  if (spread) {
    bucket_side = std::max(1, (w + grid_columns - 1) / grid_columns);
    bucket_columns = (w + bucket_side - 1) / bucket_side;
    const int bucket_rows = (h - first_row + bucket_side - 1) / bucket_side;
    const int buckets = std::max(1, bucket_columns * bucket_rows);
    bucket_cap = std::max(1, (max_corners + buckets - 1) / buckets);
    bucket_counts_.assign(static_cast<std::size_t>(buckets), 0);
    bucket_threshold_.assign(static_cast<std::size_t>(buckets), 0.0f);
  }
  // The strongest response where corners may be, and each cell's: the columns' maxima over a
  // row of cells (over all rows without cells), then over each cell's columns.
  const auto as_float = [](std::int32_t bits) {
    float value;
    std::memcpy(&value, &bits, sizeof value);
    return value;
  };
  float strongest = 0.0f;
  const int band = spread ? bucket_side : h - first_row;
  for (int y0 = first_row; y0 < h; y0 += band) {
    column_max_.assign(static_cast<std::size_t>(w), 0);
    raiseColumnMaxima(response_, depth, y0, std::min(y0 + band, h), column_max_.data());
    if (!spread) {
      strongest =
          std::max(strongest, as_float(*std::max_element(column_max_.begin(), column_max_.end())));
      continue;
    }
    float* cell_max = &bucket_threshold_[static_cast<std::size_t>((y0 - first_row) / bucket_side) *
                                         bucket_columns];
    for (int c = 0; c < bucket_columns; ++c) {
      const auto x = column_max_.begin() + c * bucket_side;
      cell_max[c] =
          as_float(*std::max_element(x, column_max_.begin() + std::min((c + 1) * bucket_side, w)));
      strongest = std::max(strongest, cell_max[c]);
    }
  }
  const auto threshold = static_cast<float>(strongest * quality);
  if (spread) {
    const auto floor = static_cast<float>(strongest * quality * kCellQualityFloor);
    for (float& t : bucket_threshold_)
      t = std::max(static_cast<float>(t * quality), floor);
  }
  // Each pixel's bar in the row: its cell's, set again where a row of cells starts.
  row_threshold_.assign(static_cast<std::size_t>(w), threshold);
  int bar_cell_row = -1;
  candidates_.clear();
  is_peak_.resize(static_cast<std::size_t>(w));
  for (int y = std::max(first_row, 1); y + 1 < h; ++y) {
    const float* __restrict above = response_.ptr<float>(y - 1);
    const float* __restrict r = response_.ptr<float>(y);
    const float* __restrict below = response_.ptr<float>(y + 1);
    const float* __restrict z = depth.ptr<float>(y);
    std::uint8_t* __restrict peak = is_peak_.data();
    if (spread && (y - first_row) / bucket_side != bar_cell_row) {
      bar_cell_row = (y - first_row) / bucket_side;
      const float* cell =
          &bucket_threshold_[static_cast<std::size_t>(bar_cell_row) * bucket_columns];
      for (int c = 0; c < bucket_columns; ++c) {
        const int x = c * bucket_side;
        std::fill(row_threshold_.begin() + x, row_threshold_.begin() + std::min(x + bucket_side, w),
                  cell[c]);
      }
    }
    const float* __restrict bar = row_threshold_.data();
    // Branch-free (it vectorises): above the threshold, with depth, no neighbour stronger.
    for (int x = 1; x + 1 < w; ++x) {
      const float v = r[x];
      peak[x] = (v > bar[x]) & (z[x] == z[x]) & (v >= r[x - 1]) & (v >= r[x + 1]) &
                (v >= above[x - 1]) & (v >= above[x]) & (v >= above[x + 1]) & (v >= below[x - 1]) &
                (v >= below[x]) & (v >= below[x + 1]);
    }
    for (int x = 1; x + 1 < w;) {
      std::uint64_t eight;  // most pixels are no peak: skip them eight at a time
      if (x + 8 < w) {
        std::memcpy(&eight, peak + x, sizeof eight);
        if (eight == 0) {
          x += 8;
          continue;
        }
      }
      if (peak[x]) candidates_.emplace_back(r[x], static_cast<std::int64_t>(y) * w + x);
      ++x;
    }
  }
  // Strongest first; among equals the later pixel first (as OpenCV's order by address).
  std::sort(candidates_.begin(), candidates_.end(),
            [](const auto& a, const auto& b) { return a > b; });

  const auto room = [&] {
    return max_corners <= 0 || corners_.size() < static_cast<std::size_t>(max_corners);
  };
  // False when the corner's spreading cell is full; else counts it there.
  const auto admitted = [&](int x, int y) {
    if (bucket_side == 0) return true;
    int& count =
        bucket_counts_[static_cast<std::size_t>((y - first_row) / bucket_side) * bucket_columns +
                       x / bucket_side];
    if (count >= bucket_cap) return false;
    ++count;
    return true;
  };
  if (min_distance < 1.0) {
    for (std::size_t k = 0; k < candidates_.size() && room(); ++k) {
      const auto index = candidates_[k].second;
      const auto x = static_cast<int>(index % w), y = static_cast<int>(index / w);
      if (!admitted(x, y)) continue;
      corners_.emplace_back(static_cast<float>(x), static_cast<float>(y));
    }
    return corners_;
  }
  // Beyond the image's diagonal every pair is nearer: the same corners as at the diagonal.
  min_distance = std::min(min_distance, std::hypot(w, h) + 1.0);
  // Kept corners by cell; cells within `reach` of a corner's cell hold every kept corner nearer
  // than min_distance.
  const int cell = static_cast<int>(std::lround(min_distance));
  const int reach = static_cast<int>(std::ceil(min_distance / cell));
  const int grid_w = (w + cell - 1) / cell, grid_h = (h + cell - 1) / cell;
  cells_.resize(static_cast<std::size_t>(grid_w) * grid_h);
  for (auto& kept : cells_)
    kept.clear();
  const double min_distance2 = min_distance * min_distance;
  for (std::size_t k = 0; k < candidates_.size() && room(); ++k) {
    const auto index = candidates_[k].second;
    const auto x = static_cast<int>(index % w), y = static_cast<int>(index / w);
    const int cx = x / cell, cy = y / cell;
    bool far_enough = true;
    for (int gy = std::max(cy - reach, 0); far_enough && gy <= std::min(cy + reach, grid_h - 1);
         ++gy) {
      for (int gx = std::max(cx - reach, 0); far_enough && gx <= std::min(cx + reach, grid_w - 1);
           ++gx) {
        for (const cv::Point2f& p : cells_[static_cast<std::size_t>(gy) * grid_w + gx]) {
          const float ex = static_cast<float>(x) - p.x, ey = static_cast<float>(y) - p.y;
          if (ex * ex + ey * ey < min_distance2) {
            far_enough = false;
            break;
          }
        }
      }
    }
    if (!far_enough || !admitted(x, y)) continue;
    const cv::Point2f corner(static_cast<float>(x), static_cast<float>(y));
    cells_[static_cast<std::size_t>(cy) * grid_w + cx].push_back(corner);
    corners_.push_back(corner);
  }
  return corners_;
}

}  // namespace cvo
