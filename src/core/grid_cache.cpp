#include "cvo_odometry/core/grid_cache.hpp"

#include <algorithm>
#include <cstring>

namespace cvo {

GridCache::GridCache(std::size_t capacity) : entries_(std::max<std::size_t>(capacity, 1)) {}

bool GridCache::holds(const Entry& entry, const float* positions, std::size_t count,
                      float cell_size) {
  return entry.valid && entry.cell_size == cell_size && entry.positions.size() == 3 * count &&
         (count == 0 ||
          std::memcmp(entry.positions.data(), positions, 3 * count * sizeof(float)) == 0);
}

const VoxelGrid& GridCache::grid(const float* positions, std::size_t count, float cell_size) {
  ++clock_;
  for (Entry& entry : entries_) {
    if (holds(entry, positions, count, cell_size)) {
      entry.last_used = clock_;
      return entry.grid;
    }
  }
  Entry& entry =
      *std::min_element(entries_.begin(), entries_.end(),
                        [](const Entry& a, const Entry& b) { return a.last_used < b.last_used; });
  // Invalid until whole: a build that throws (allocation) leaves no entry claiming its grid.
  entry.valid = false;
  entry.grid.build(positions, count, cell_size);
  entry.positions.assign(positions, positions + 3 * count);
  entry.cell_size = cell_size;
  entry.valid = true;
  entry.last_used = clock_;
  ++builds_;
  return entry.grid;
}

}  // namespace cvo
