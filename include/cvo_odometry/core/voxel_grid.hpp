// Uniform grid over a point set for fixed-radius neighbour queries. Points are sorted by cell
// (counting sort); where the bounding box spans few enough cells the grid is dense, with the
// z cells of one (x, y) column contiguous so that a query reads 9 ranges; over larger extents
// (outdoor scenes) occupied cells are found through a hash map instead.
#pragma once

#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "cvo_odometry/core/dense_grid.hpp"

namespace cvo {

class VoxelGrid {
 public:
  // `positions` holds 3 floats a point and must outlive the grid's use; `cell_size` should be
  // the largest query radius.
  void build(const float* positions, std::size_t count, float cell_size);

  float cellSize() const { return shape_.cell; }

  // Calls f(index, squared distance) for every point within `radius` (<= cell size) of p, in a
  // fixed order.
  template <class F>
  void forEachWithin(const float* p, float radius, F&& f) const {
    const float r2 = radius * radius;
    auto visit = [&](std::uint32_t begin, std::uint32_t end) {
      for (std::uint32_t k = begin; k < end; ++k) {
        const float* q = sorted_ + 3 * k;
        const float ex = q[0] - p[0], ey = q[1] - p[1], ez = q[2] - p[2];
        const float d2 = ex * ex + ey * ey + ez * ez;
        if (d2 <= r2) f(order_[k], d2);
      }
    };
    if (dense_) {
      kernels::forEachNeighbourRange(shape_, start_.data(), p, visit);
      return;
    }
    const int cx = kernels::cellCoordinate(shape_, p[0], 0);
    const int cy = kernels::cellCoordinate(shape_, p[1], 1);
    const int cz = kernels::cellCoordinate(shape_, p[2], 2);
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(key(cx + dx, cy + dy, cz + dz));
          if (it != cells_.end()) visit(it->second.first, it->second.second);
        }
      }
    }
  }

 private:
  static std::uint64_t key(int x, int y, int z);

  kernels::DenseGridShape shape_{{0.0f, 0.0f, 0.0f}, 0.0f, {0, 0, 0}};
  bool dense_ = true;
  std::vector<std::uint32_t> start_;  // dense: first sorted point of each cell, plus the end
  std::unordered_map<std::uint64_t, std::pair<std::uint32_t, std::uint32_t>> cells_;  // sparse
  std::vector<std::uint32_t> order_;   // sorted slot -> point index
  std::vector<float> sorted_storage_;  // positions in sorted order: queries read contiguously
  const float* sorted_ = nullptr;
};

}  // namespace cvo
