// Uniform grid over a point set for fixed-radius neighbour queries. Points are sorted by cell
// (counting sort); where the bounding box spans few enough cells the grid is dense, with the
// z cells of one (x, y) column contiguous so that a query reads 9 ranges; over larger extents
// (outdoor scenes) occupied cells are found through a hash map instead.
#pragma once

#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace cvo {

class VoxelGrid {
 public:
  // `positions` holds 3 floats a point and must outlive the grid's use; `cell_size` should be
  // the largest query radius.
  void build(const float* positions, std::size_t count, float cell_size);

  float cellSize() const { return cell_size_; }

  // Calls f(index, squared distance) for every point within `radius` (<= cell size) of p, in a
  // fixed order.
  template <class F>
  void forEachWithin(const float* p, float radius, F&& f) const {
    const float r2 = radius * radius;
    const int cx = cellCoord(p[0], 0), cy = cellCoord(p[1], 1), cz = cellCoord(p[2], 2);
    auto visit = [&](std::uint32_t begin, std::uint32_t end) {
      for (std::uint32_t k = begin; k < end; ++k) {
        const float* q = sorted_ + 3 * k;
        const float ex = q[0] - p[0], ey = q[1] - p[1], ez = q[2] - p[2];
        const float d2 = ex * ex + ey * ey + ez * ez;
        if (d2 <= r2) f(order_[k], d2);
      }
    };
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        if (dense_) {
          const int x = cx + dx, y = cy + dy;
          if (x < 0 || y < 0 || x >= dims_[0] || y >= dims_[1]) continue;
          const int z0 = std::max(cz - 1, 0), z1 = std::min(cz + 1, dims_[2] - 1);
          if (z0 > z1) continue;
          const std::size_t column = (static_cast<std::size_t>(x) * dims_[1] + y) * dims_[2];
          visit(start_[column + z0], start_[column + z1 + 1]);
        } else {
          for (int dz = -1; dz <= 1; ++dz) {
            const auto it = cells_.find(key(cx + dx, cy + dy, cz + dz));
            if (it != cells_.end()) visit(it->second.first, it->second.second);
          }
        }
      }
    }
  }

 private:
  int cellCoord(float v, int axis) const;
  static std::uint64_t key(int x, int y, int z);

  float cell_size_ = 0.0f;
  float origin_[3] = {0.0f, 0.0f, 0.0f};
  bool dense_ = true;
  int dims_[3] = {0, 0, 0};
  std::vector<std::uint32_t> start_;  // dense: first sorted point of each cell, plus the end
  std::unordered_map<std::uint64_t, std::pair<std::uint32_t, std::uint32_t>> cells_;  // sparse
  std::vector<std::uint32_t> order_;   // sorted slot -> point index
  std::vector<float> sorted_storage_;  // positions in sorted order: queries read contiguously
  const float* sorted_ = nullptr;
};

}  // namespace cvo
