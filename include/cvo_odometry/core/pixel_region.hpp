// A region of an image kept as a grid of small cells: where an object moving through the view
// was seen (discs around its feature tracks). The odometry leaves the points inside it out of a
// frame's cloud, and the photometric stage the reference image's pixels inside it.
#pragma once

#include <cstdint>
#include <vector>

namespace cvo {

class PixelRegion {
 public:
  // An empty region of a width x height image; cells of cell_px (>= 1) a side.
  PixelRegion(int width, int height, int cell_px = 8);

  // Adds every cell within `radius` px of (u, v) (a cell counts when its nearest point is).
  void addDisc(double u, double v, double radius);
  // Fills the gaps narrower than 2 * radius between the region's parts (a morphological closing
  // on the cells): the untextured inside of an object between its tracks' discs.
  void closeGaps(double radius);
  // (u, v) is in a cell of the region; false outside the image.
  bool contains(double u, double v) const;
  bool empty() const { return marked_ == 0; }
  // The share of the image's cells in the region.
  double coveredFraction() const;
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  int width_, height_, cell_, columns_, rows_;
  std::vector<std::uint8_t> cells_;
  std::size_t marked_ = 0;
};

}  // namespace cvo
