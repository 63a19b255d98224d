#include "cvo_odometry/core/voxel_grid.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace cvo {

std::uint64_t VoxelGrid::key(int x, int y, int z) {
  // 21 bits per axis around an offset: cells of 1 cm still span +-10 km.
  constexpr std::uint64_t kMask = (1u << 21) - 1;
  constexpr int kOffset = 1 << 20;
  return ((static_cast<std::uint64_t>(x + kOffset) & kMask) << 42) |
         ((static_cast<std::uint64_t>(y + kOffset) & kMask) << 21) |
         (static_cast<std::uint64_t>(z + kOffset) & kMask);
}

void VoxelGrid::build(const float* positions, std::size_t count, float cell_size) {
  float lo[3], hi[3];
  kernels::boundingBox(positions, count, lo, hi);
  const double cells = kernels::shapeOverBox(lo, hi, cell_size, &shape_);
  dense_ = cells <= kernels::kMaxDenseCells;

  std::vector<std::uint64_t> cell_of(count);
  for (std::size_t i = 0; i < count; ++i) {
    const float* p = positions + 3 * i;
    cell_of[i] = dense_ ? kernels::cellOfPoint(shape_, p)
                        : key(kernels::cellCoordinate(shape_, p[0], 0),
                              kernels::cellCoordinate(shape_, p[1], 1),
                              kernels::cellCoordinate(shape_, p[2], 2));
  }
  order_.resize(count);
  if (dense_) {
    // Counting sort: stable, so the order within a cell is the input order. The slots are
    // filled from each cell's end, the points taken backwards, so that start_ itself counts
    // down to each cell's first slot (no second cell-sized array: TUM's finest grids have
    // 0.5M cells for 9k points).
    const auto cell_count = static_cast<std::size_t>(cells);
    start_.assign(cell_count + 1, 0u);
    for (std::size_t i = 0; i < count; ++i)
      ++start_[cell_of[i] + 1];
    std::partial_sum(start_.begin(), start_.end(), start_.begin());  // [c + 1]: cell c's end
    for (std::size_t i = count; i-- > 0;)
      order_[--start_[cell_of[i] + 1]] = static_cast<std::uint32_t>(i);
    // [c + 1] is now cell c's first slot: shift down and close with the end.
    std::copy(start_.begin() + 1, start_.end(), start_.begin());
    start_[cell_count] = static_cast<std::uint32_t>(count);
    cells_.clear();
  } else {
    std::iota(order_.begin(), order_.end(), 0u);
    std::stable_sort(order_.begin(), order_.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return cell_of[a] < cell_of[b]; });
    std::size_t occupied = 0;
    for (std::size_t k = 0; k < count; ++k)
      occupied += k == 0 || cell_of[order_[k]] != cell_of[order_[k - 1]];
    cells_.reset(occupied);
    for (std::uint32_t k = 0; k < count;) {
      std::uint32_t end = k + 1;
      while (end < count && cell_of[order_[end]] == cell_of[order_[k]])
        ++end;
      cells_.insert(cell_of[order_[k]], {k, end});
      k = end;
    }
    start_.clear();
  }
  xs_.resize(count);
  ys_.resize(count);
  zs_.resize(count);
  for (std::size_t k = 0; k < count; ++k) {
    const float* p = positions + 3 * order_[k];
    xs_[k] = p[0];
    ys_[k] = p[1];
    zs_[k] = p[2];
  }
}

}  // namespace cvo
