#include "cvo_odometry/frontend/point_spacing.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "cvo_odometry/core/voxel_grid.hpp"

namespace cvo {

PointSpacing::PointSpacing(double spacing, std::size_t points) {
  if (!(spacing >= 0.0) || !std::isfinite(spacing)) {
    throw std::invalid_argument("point spacing must be finite and >= 0, got " +
                                std::to_string(spacing));
  }
  if (spacing == 0.0) return;
  inverse_spacing_ = 1.0 / spacing;
  occupied_.reset(points);
}

bool PointSpacing::admit(const Eigen::Vector3f& point) {
  if (inverse_spacing_ == 0.0) return true;
  int cube[3];
  for (int a = 0; a < 3; ++a) {
    const double c = std::floor(static_cast<double>(point[a]) * inverse_spacing_);
    if (!(std::abs(c) < VoxelGrid::kSparseReach)) return true;
    cube[a] = static_cast<int>(c);
  }
  const std::uint64_t key = VoxelGrid::key(cube[0], cube[1], cube[2]);
  if (occupied_.find(key)) return false;
  occupied_.insert(key, {0u, 0u});
  return true;
}

}  // namespace cvo
