// Uniform hash grid over a point set for fixed-radius neighbour queries: points sorted by cell,
// one hash entry per occupied cell. Built in O(n log n); a query visits the 27 cells around it.
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

namespace cvo {

class VoxelGrid {
 public:
  // `positions` holds 3 floats a point; `cell_size` should be the largest query radius.
  void build(const float* positions, std::size_t count, float cell_size);

  float cellSize() const { return cell_size_; }

  // Calls f(index) for every point within `radius` (<= cell size) of p, in a fixed order.
  template <class F>
  void forEachWithin(const float* p, float radius, F&& f) const {
    const float r2 = radius * radius;
    const int cx = cellCoord(p[0]), cy = cellCoord(p[1]), cz = cellCoord(p[2]);
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(key(cx + dx, cy + dy, cz + dz));
          if (it == cells_.end()) continue;
          for (std::uint32_t k = it->second.first; k < it->second.second; ++k) {
            const std::uint32_t i = order_[k];
            const float* q = positions_ + 3 * i;
            const float ex = q[0] - p[0], ey = q[1] - p[1], ez = q[2] - p[2];
            if (ex * ex + ey * ey + ez * ez <= r2) f(i);
          }
        }
      }
    }
  }

 private:
  int cellCoord(float v) const;
  static std::uint64_t key(int x, int y, int z);

  const float* positions_ = nullptr;
  float cell_size_ = 1.0f;
  std::vector<std::uint32_t> order_;  // point indices sorted by cell
  std::unordered_map<std::uint64_t, std::pair<std::uint32_t, std::uint32_t>> cells_;
};

}  // namespace cvo
