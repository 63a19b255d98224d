#include "cvo_odometry/core/voxel_grid.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace cvo {

int VoxelGrid::cellCoord(float v) const {
  return static_cast<int>(std::floor(v / cell_size_));
}

std::uint64_t VoxelGrid::key(int x, int y, int z) {
  // 21 bits per axis around an offset: cells of 1 cm still span +-10 km.
  constexpr std::uint64_t kMask = (1u << 21) - 1;
  constexpr int kOffset = 1 << 20;
  return ((static_cast<std::uint64_t>(x + kOffset) & kMask) << 42) |
         ((static_cast<std::uint64_t>(y + kOffset) & kMask) << 21) |
         (static_cast<std::uint64_t>(z + kOffset) & kMask);
}

void VoxelGrid::build(const float* positions, std::size_t count, float cell_size) {
  positions_ = positions;
  cell_size_ = cell_size;
  std::vector<std::uint64_t> keys(count);
  for (std::size_t i = 0; i < count; ++i) {
    const float* p = positions + 3 * i;
    keys[i] = key(cellCoord(p[0]), cellCoord(p[1]), cellCoord(p[2]));
  }
  order_.resize(count);
  std::iota(order_.begin(), order_.end(), 0u);
  std::stable_sort(order_.begin(), order_.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return keys[a] < keys[b]; });
  cells_.clear();
  cells_.reserve(count);
  for (std::uint32_t k = 0; k < count;) {
    std::uint32_t end = k + 1;
    while (end < count && keys[order_[end]] == keys[order_[k]])
      ++end;
    cells_.emplace(keys[order_[k]], std::make_pair(k, end));
    k = end;
  }
}

}  // namespace cvo
