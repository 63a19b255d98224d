// The arithmetic of the dense neighbour grid, written once for the CPU VoxelGrid and the CUDA
// kernels: the target sorted by cell, the z cells of one (x, y) column contiguous, so that the
// candidates within one cell of a point lie in 9 index ranges of the sorted order.
#pragma once

#include <math.h>

#include "cvo_odometry/core/pair_kernels.hpp"  // CVO_HOST_DEVICE

namespace cvo {
namespace kernels {

struct DenseGridShape {
  float origin[3];  // the bounding box's lower corner
  float cell;       // edge of a cubic cell (>= the query radius)
  int dims[3];      // cells per axis
};

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

// Calls visit(begin, end) for the sorted-order ranges of the 9 (x, y) columns around p's cell,
// each over the z cells p's cell and its two z neighbours span; `start` holds the first sorted
// index of every cell and, last, the point count. Fixed order: deterministic sums.
template <class Visit>
CVO_HOST_DEVICE inline void forEachNeighbourRange(const DenseGridShape& g, const unsigned* start,
                                                  const float* p, Visit&& visit) {
  const int cx = cellCoordinate(g, p[0], 0);
  const int cy = cellCoordinate(g, p[1], 1);
  const int cz = cellCoordinate(g, p[2], 2);
  for (int dx = -1; dx <= 1; ++dx) {
    for (int dy = -1; dy <= 1; ++dy) {
      const int x = cx + dx, y = cy + dy;
      if (x < 0 || y < 0 || x >= g.dims[0] || y >= g.dims[1]) continue;
      const int z0 = cz - 1 < 0 ? 0 : cz - 1;
      const int z1 = cz + 1 > g.dims[2] - 1 ? g.dims[2] - 1 : cz + 1;
      if (z0 > z1) continue;
      const unsigned long long column = flatCell(g, x, y, 0);
      visit(start[column + z0], start[column + z1 + 1]);
    }
  }
}

}  // namespace kernels
}  // namespace cvo
