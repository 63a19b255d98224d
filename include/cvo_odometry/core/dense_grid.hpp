// The arithmetic of the dense neighbour grid, written once for the CPU VoxelGrid and the CUDA
// kernels: the target sorted by cell, the z cells of one (x, y) column contiguous, so that the
// candidates within a radius of a point lie in a few index ranges of the sorted order.
#pragma once

#include <math.h>
#include <stddef.h>

#include <cstddef>

#include "cvo_odometry/core/pair_kernels.hpp"  // CVO_HOST_DEVICE

namespace cvo {
namespace kernels {

struct DenseGridShape {
  float origin[3];  // the bounding box's lower corner
  float cell;       // edge of a cubic cell (>= the query radius)
  int dims[3];      // cells per axis
};

// Dense grids up to this many cells (16 MB of offsets); beyond, the CPU hashes its cells and the
// GPU coarsens them.
constexpr double kMaxDenseCells = 4.0e6;

// Host side: the bounding box of `count` points (3 floats each); an empty set gives a zero box.
inline void boundingBox(const float* positions, std::size_t count, float* lo, float* hi) {
  for (int a = 0; a < 3; ++a)
    lo[a] = hi[a] = count ? positions[a] : 0.0f;
  for (std::size_t i = 0; i < count; ++i) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = fminf(lo[a], positions[3 * i + a]);
      hi[a] = fmaxf(hi[a], positions[3 * i + a]);
    }
  }
}

// Host side: cells of edge `cell` from the box's lower corner over [lo, hi]; returns the cell
// count.
inline double shapeOverBox(const float* lo, const float* hi, float cell, DenseGridShape* shape) {
  shape->cell = cell;
  double cells = 1.0;
  for (int a = 0; a < 3; ++a) {
    shape->origin[a] = lo[a];
    shape->dims[a] = static_cast<int>(floorf((hi[a] - lo[a]) / cell)) + 1;
    cells *= shape->dims[a];
  }
  return cells;
}

CVO_HOST_DEVICE inline int cellCoordinate(const DenseGridShape& g, float v, int axis) {
  return static_cast<int>(floorf((v - g.origin[axis]) / g.cell));
}

CVO_HOST_DEVICE inline unsigned long long flatCell(const DenseGridShape& g, int x, int y, int z) {
  return (static_cast<unsigned long long>(x) * g.dims[1] + y) * g.dims[2] + z;
}

// The cell of a point of the box; clamped, since rounding can put a point on the far face.
CVO_HOST_DEVICE inline unsigned long long cellOfPoint(const DenseGridShape& g, const float* p) {
  int c[3];
  for (int a = 0; a < 3; ++a) {
    const int k = cellCoordinate(g, p[a], a);
    c[a] = k < 0 ? 0 : (k >= g.dims[a] ? g.dims[a] - 1 : k);
  }
  return flatCell(g, c[0], c[1], c[2]);
}

// A cell coordinate range [first, last] clamped to [0, dims - 1] before any float -> int
// conversion (a far or non-finite point must not overflow the cast): empty when first > last.
CVO_HOST_DEVICE inline void clampedCellRange(float low, float high, int dims, int& first,
                                             int& last) {
  const float top = static_cast<float>(dims);
  // fmaxf/fminf return the number when the other operand is NaN: NaN ends up an empty range.
  low = fminf(fmaxf(floorf(low), 0.0f), top);
  high = fminf(fmaxf(floorf(high), -1.0f), top - 1.0f);
  first = static_cast<int>(low);
  last = static_cast<int>(high);
}

// Calls visit(begin, end) for sorted-order ranges that together hold every point within `radius`
// of p (and some beyond): for each (x, y) column whose footprint comes within the radius, the run
// of z cells the radius spans. Any cell size works (the radius may span several cells); `start`
// holds the first sorted index of every cell and, last, the point count. Fixed order:
// deterministic sums.
template <class Visit>
CVO_HOST_DEVICE inline void forEachRangeWithin(const DenseGridShape& g, const unsigned* start,
                                               const float* p, float radius, Visit&& visit) {
  // In cell units, as cellCoordinate divides; the slack covers that division's rounding.
  const float lx = (p[0] - g.origin[0]) / g.cell, ly = (p[1] - g.origin[1]) / g.cell;
  const float lz = (p[2] - g.origin[2]) / g.cell;
  const float reach = radius / g.cell * 1.00001f + 1e-6f;
  int x0, x1, y0, y1, z0, z1;
  clampedCellRange(lx - reach, lx + reach, g.dims[0], x0, x1);
  clampedCellRange(ly - reach, ly + reach, g.dims[1], y0, y1);
  clampedCellRange(lz - reach, lz + reach, g.dims[2], z0, z1);
  if (z0 > z1) return;
  const float reach2 = reach * reach;
  for (int x = x0; x <= x1; ++x) {
    // Distance from p to the column's footprint along x (0 inside it).
    const float ex = lx < x ? x - lx : (lx > x + 1 ? lx - (x + 1) : 0.0f);
    for (int y = y0; y <= y1; ++y) {
      const float ey = ly < y ? y - ly : (ly > y + 1 ? ly - (y + 1) : 0.0f);
      if (ex * ex + ey * ey > reach2) continue;
      const unsigned long long column = flatCell(g, x, y, 0);
      visit(start[column + z0], start[column + z1 + 1]);
    }
  }
}

}  // namespace kernels
}  // namespace cvo
