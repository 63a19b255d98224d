#include "cvo_odometry/core/pixel_region.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace cvo {

PixelRegion::PixelRegion(int width, int height, int cell_px)
    : width_(width), height_(height), cell_(cell_px) {
  if (width < 1 || height < 1 || cell_px < 1) {
    throw std::invalid_argument("a pixel region needs a positive image size and cell size");
  }
  columns_ = (width + cell_ - 1) / cell_;
  rows_ = (height + cell_ - 1) / cell_;
  cells_.assign(static_cast<std::size_t>(columns_) * rows_, 0);
}

void PixelRegion::addDisc(double u, double v, double radius) {
  if (!std::isfinite(u) || !std::isfinite(v) || !(radius >= 0.0)) return;
  const int c0 = std::max(0, static_cast<int>(std::floor((u - radius) / cell_)));
  const int c1 = std::min(columns_ - 1, static_cast<int>(std::floor((u + radius) / cell_)));
  const int r0 = std::max(0, static_cast<int>(std::floor((v - radius) / cell_)));
  const int r1 = std::min(rows_ - 1, static_cast<int>(std::floor((v + radius) / cell_)));
  for (int r = r0; r <= r1; ++r) {
    for (int c = c0; c <= c1; ++c) {
      // The cell's nearest point to (u, v).
      const double x = std::clamp(u, static_cast<double>(c * cell_), (c + 1.0) * cell_);
      const double y = std::clamp(v, static_cast<double>(r * cell_), (r + 1.0) * cell_);
      if ((x - u) * (x - u) + (y - v) * (y - v) > radius * radius) continue;
      std::uint8_t& cell = cells_[static_cast<std::size_t>(r) * columns_ + c];
      if (cell == 0) ++marked_;
      cell = 1;
    }
  }
}

void PixelRegion::closeGaps(double radius) {
  const int r = static_cast<int>(std::ceil(radius / cell_));
  if (r < 1 || marked_ == 0) return;
  // Square structuring elements, separable: rows, then columns.
  const auto pass = [&](const std::vector<std::uint8_t>& in, bool grow, bool along_rows) {
    std::vector<std::uint8_t> out(in.size());
    for (int y = 0; y < rows_; ++y) {
      for (int x = 0; x < columns_; ++x) {
        bool any = false, all = true;
        for (int d = -r; d <= r; ++d) {
          const int xx = along_rows ? x + d : x, yy = along_rows ? y : y + d;
          // Beyond the image counts as marked for the erosion: a region at the border stays.
          const bool in_image = xx >= 0 && yy >= 0 && xx < columns_ && yy < rows_;
          const bool marked =
              in_image ? in[static_cast<std::size_t>(yy) * columns_ + xx] != 0 : !grow;
          any = any || marked;
          all = all && marked;
        }
        out[static_cast<std::size_t>(y) * columns_ + x] = grow ? any : all;
      }
    }
    return out;
  };
  cells_ = pass(pass(pass(pass(cells_, true, true), true, false), false, true), false, false);
  marked_ = static_cast<std::size_t>(std::count(cells_.begin(), cells_.end(), 1));
}

bool PixelRegion::contains(double u, double v) const {
  if (!(u >= 0.0 && v >= 0.0 && u < width_ && v < height_)) return false;
  return cells_[static_cast<std::size_t>(v / cell_) * columns_ +
                static_cast<std::size_t>(u / cell_)] != 0;
}

double PixelRegion::coveredFraction() const {
  return static_cast<double>(marked_) / static_cast<double>(cells_.size());
}

}  // namespace cvo
