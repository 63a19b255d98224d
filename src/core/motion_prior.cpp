#include "cvo_odometry/core/motion_prior.hpp"

namespace cvo {

double trackAgreement(const MotionPrior& prior, const Eigen::Isometry3d& motion,
                      double max_error_px) {
  if (prior.points.empty() || !(prior.focal_px > 0.0)) return -1.0;
  const Eigen::Isometry3d current_from_keyframe = motion.inverse();
  const double max_error = max_error_px / prior.focal_px;
  std::size_t within = 0;
  for (std::size_t i = 0; i < prior.points.size(); ++i) {
    const Eigen::Vector3d p = current_from_keyframe * prior.points[i];
    if (!(p.z() > 1e-6)) continue;
    if ((p.head<2>() / p.z() - prior.observations[i]).norm() <= max_error) ++within;
  }
  return static_cast<double>(within) / static_cast<double>(prior.points.size());
}

}  // namespace cvo
