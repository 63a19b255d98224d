// Uniform grid over a point set for fixed-radius neighbour queries. Points are sorted by cell
// (counting sort) and kept as separate x, y, z arrays in that order, so that the candidates of a
// query are a few contiguous ranges a vectorised loop can read. Where the bounding box spans few
// enough cells the grid is dense, with the z cells of one (x, y) column contiguous (one range a
// column); over larger extents (outdoor scenes) occupied cells are found through a hash table.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "cvo_odometry/core/cell_hash_table.hpp"
#include "cvo_odometry/core/dense_grid.hpp"

namespace cvo {

class VoxelGrid {
 public:
  // `positions` holds 3 floats a point; the grid keeps its own sorted copy.
  void build(const float* positions, std::size_t count, float cell_size);

  float cellSize() const { return shape_.cell; }

  // Calls visit(begin, end) for ranges of the sorted order that together hold every point within
  // `radius` of p (and some beyond), in a fixed order.
  template <class Visit>
  void forEachRange(const float* p, float radius, Visit&& visit) const {
    if (dense_) {
      kernels::forEachRangeWithin(shape_, start_.data(), p, radius, visit);
      return;
    }
    int first[3], last[3];
    for (int a = 0; a < 3; ++a) {
      const float low = (p[a] - radius - shape_.origin[a]) / shape_.cell;
      const float high = (p[a] + radius - shape_.origin[a]) / shape_.cell;
      // The hash keys hold 21 bits an axis: clamp before converting (far or non-finite points).
      first[a] = static_cast<int>(std::fmax(std::floor(low), -kSparseReach));
      last[a] = static_cast<int>(std::fmin(std::floor(high), kSparseReach));
    }
    for (int x = first[0]; x <= last[0]; ++x) {
      for (int y = first[1]; y <= last[1]; ++y) {
        for (int z = first[2]; z <= last[2]; ++z) {
          if (const CellHashTable::Range* range = cells_.find(key(x, y, z))) {
            visit(range->first, range->second);
          }
        }
      }
    }
  }

  // Calls f(index, squared distance) for every point within `radius` of p, in a fixed order.
  template <class F>
  void forEachWithin(const float* p, float radius, F&& f) const {
    const float r2 = radius * radius;
    forEachRange(p, radius, [&](std::uint32_t begin, std::uint32_t end) {
      for (std::uint32_t k = begin; k < end; ++k) {
        const float ex = xs_[k] - p[0], ey = ys_[k] - p[1], ez = zs_[k] - p[2];
        const float d2 = ex * ex + ey * ey + ez * ez;
        if (d2 <= r2) f(order_[k], d2);
      }
    });
  }

  // Whether a point lies within `radius` of p (the ranges' points are skipped once one does).
  bool anyWithin(const float* p, float radius) const {
    const float r2 = radius * radius;
    bool found = false;
    forEachRange(p, radius, [&](std::uint32_t begin, std::uint32_t end) {
      for (std::uint32_t k = begin; k < end && !found; ++k) {
        const float ex = xs_[k] - p[0], ey = ys_[k] - p[1], ez = zs_[k] - p[2];
        found = ex * ex + ey * ey + ez * ez <= r2;
      }
    });
    return found;
  }

  // The points in sorted order (the slots forEachRange's ranges index).
  const float* sortedX() const { return xs_.data(); }
  const float* sortedY() const { return ys_.data(); }
  const float* sortedZ() const { return zs_.data(); }

  // The hash key of cell (x, y, z): 21 bits an axis, distinct for coordinates within
  // +-kSparseReach.
  static constexpr float kSparseReach = 1 << 20;
  static std::uint64_t key(int x, int y, int z);

 private:
  kernels::DenseGridShape shape_{{0.0f, 0.0f, 0.0f}, 0.0f, {0, 0, 0}};
  bool dense_ = true;
  std::vector<std::uint32_t> start_;  // dense: first sorted point of each cell, plus the end
  CellHashTable cells_;               // sparse: occupied cells
  std::vector<std::uint32_t> order_;  // sorted slot -> point index
  std::vector<float> xs_, ys_, zs_;   // positions in sorted order
};

}  // namespace cvo
