#include "cvo_odometry/core/motion_prior.hpp"

#include <algorithm>
#include <vector>

#include "cvo_odometry/core/robust_scale.hpp"

namespace cvo {

TrackAgreement trackAgreement(const MotionPrior& prior, const Eigen::Isometry3d& motion,
                              double max_error_px) {
  TrackAgreement agreement;
  if (prior.points.empty() || !(prior.focal_px > 0.0)) return agreement;
  const Eigen::Isometry3d current_from_previous = motion.inverse();
  std::vector<double> errors, flows;
  errors.reserve(prior.points.size());
  for (std::size_t i = 0; i < prior.points.size(); ++i) {
    const Eigen::Vector3d& X = prior.points[i];
    flows.push_back(prior.focal_px * (X.head<2>() / X.z() - prior.observations[i]).norm());
    const Eigen::Vector3d p = current_from_previous * prior.points[i];
    errors.push_back(p.z() > 1e-6
                         ? prior.focal_px * (p.head<2>() / p.z() - prior.observations[i]).norm()
                         : 1e9);  // behind the camera: as far off as can be
  }
  const auto within =
      std::count_if(errors.begin(), errors.end(), [&](double e) { return e <= max_error_px; });
  agreement.fraction = static_cast<double>(within) / static_cast<double>(errors.size());
  agreement.median_px = medianInPlace(errors);
  agreement.median_flow_px = medianInPlace(flows);
  return agreement;
}

}  // namespace cvo
