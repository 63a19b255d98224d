// The occupied cells of a sparse voxel grid: 63-bit cell keys to ranges of sorted points, in an
// open-addressing table (linear probing, at most half full). A neighbour query looks up 27
// cells or more per point; std::unordered_map's node chasing and modulo made those lookups a
// tenth of a KITTI frame.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

namespace cvo {

class CellHashTable {
 public:
  using Range = std::pair<std::uint32_t, std::uint32_t>;  // sorted points [first, second)

  // Empties the table and sizes it for `cells` insertions.
  void reset(std::size_t cells) {
    std::size_t slots = 16;
    int bits = 4;
    while (slots < 2 * cells) {
      slots *= 2;
      ++bits;
    }
    slots_.assign(slots, Slot{kEmpty, {0u, 0u}});
    mask_ = slots - 1;
    shift_ = 64 - bits;
  }

  // `key` must be new and below 2^63 (VoxelGrid's keys: 21 bits an axis).
  void insert(std::uint64_t key, Range range) {
    std::size_t i = slotOf(key);
    while (slots_[i].key != kEmpty)
      i = (i + 1) & mask_;
    slots_[i] = Slot{key, range};
  }

  // The range of `key`, or null when no point lies in that cell.
  const Range* find(std::uint64_t key) const {
    if (slots_.empty()) return nullptr;
    for (std::size_t i = slotOf(key);; i = (i + 1) & mask_) {
      const Slot& slot = slots_[i];
      if (slot.key == key) return &slot.range;
      if (slot.key == kEmpty) return nullptr;
    }
  }

  void clear() {
    slots_.clear();
    mask_ = 0;
    shift_ = 64;
  }

 private:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // no key has its top bit set
  struct Slot {
    std::uint64_t key;
    Range range;
  };

  std::size_t slotOf(std::uint64_t key) const {
    // Fibonacci hashing: the product's top bits depend on every bit of the key (each axis).
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_);
  }

  std::vector<Slot> slots_;
  std::size_t mask_ = 0;  // slots - 1 (a power of two)
  int shift_ = 64;        // 64 - log2(slots)
};

}  // namespace cvo
