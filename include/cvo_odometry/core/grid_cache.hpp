// The voxel grids of the last few point sets a backend asked for. A registration against a
// keyframe asks for the keyframe's grid at the same cell size every frame; building it took
// ~0.4 ms of serial work a frame at 9k points (the dense counting sort passes over ~0.2-0.5M
// cells). An entry is served only for the same cell size and the same positions, compared bit
// for bit (~10 us for 9k points), so a cloud changed in place, or a new one at a freed one's
// address, always gets a grid of its own.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "cvo_odometry/core/voxel_grid.hpp"

namespace cvo {

class GridCache {
 public:
  // Keeps the grids of the `capacity` point sets asked for last (at least 1).
  explicit GridCache(std::size_t capacity = 2);

  // The grid of `count` points (3 floats each) at `cell_size`: a kept one when it was built
  // from the same positions and cell size, else built now in place of the least recently used.
  // The reference stays valid until the next call.
  const VoxelGrid& grid(const float* positions, std::size_t count, float cell_size);

  // Grids built so far (not served from the cache).
  std::size_t builds() const { return builds_; }

 private:
  struct Entry {
    VoxelGrid grid;
    std::vector<float> positions;  // what grid was built from
    float cell_size = 0.0f;
    bool valid = false;  // false while empty or after a build that threw
    std::uint64_t last_used = 0;
  };
  static bool holds(const Entry& entry, const float* positions, std::size_t count, float cell_size);

  std::vector<Entry> entries_;
  std::uint64_t clock_ = 0;
  std::size_t builds_ = 0;
};

}  // namespace cvo
