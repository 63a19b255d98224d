#include "cvo_odometry/core/track_reprojection.hpp"

#include <algorithm>
#include <cmath>

#include "cvo_odometry/core/robust_scale.hpp"

namespace cvo {

namespace {
// Huber's threshold on a 2-D error's length, in units of the per-component scale: 95 % of
// Gaussian errors fall inside (sqrt of chi-square 2's 95 % point), as 1.345 sigma does in 1-D.
constexpr double kHuberNormScale = 2.4477;
}  // namespace

TrackReprojection::TrackReprojection(const MotionPrior& prior,
                                     const Eigen::Isometry3d& prior_from_reference)
    : focal_px_(prior.focal_px) {
  const Eigen::Isometry3d reference_from_prior = prior_from_reference.inverse();
  const std::size_t count = std::min(prior.points.size(), prior.observations.size());
  for (std::size_t i = 0; i < count; ++i) {
    points_.push_back(reference_from_prior * prior.points[i]);
    observations_.push_back(prior.observations[i]);
  }
}

bool TrackReprojection::residual(std::size_t i, const Eigen::Isometry3d& reference_from_current,
                                 Eigen::Vector2d* error,
                                 Eigen::Matrix<double, 2, 6>* jacobian) const {
  const Eigen::Isometry3d current_from_reference = reference_from_current.inverse();
  const Eigen::Vector3d& Z = points_[i];
  const Eigen::Vector3d X = current_from_reference * Z;
  if (!(X.z() > 0.0)) return false;
  const double inv_z = 1.0 / X.z();
  *error = focal_px_ * (X.head<2>() * inv_z - observations_[i]);
  if (!error->allFinite()) return false;
  Eigen::Matrix<double, 2, 3> projection;
  projection << inv_z, 0.0, -X.x() * inv_z * inv_z, 0.0, inv_z, -X.y() * inv_z * inv_z;
  // (exp(xi) T)^-1 Z = T^-1 exp(-xi) Z, and exp(-xi) Z = Z + Z x omega - v to first order.
  const Eigen::Matrix3d rotation = current_from_reference.linear();
  Eigen::Matrix<double, 3, 6> dX;
  dX << rotation * lie::hat(Z), -rotation;
  *jacobian = focal_px_ * projection * dX;
  return true;
}

std::size_t TrackReprojection::addNormalEquations(const Eigen::Isometry3d& reference_from_current,
                                                  double min_scale_px, Matrix6d* H, Vector6d* g) {
  scale_px_ = 0.0;
  const std::size_t n = points_.size();
  errors_.resize(n);
  jacobians_.resize(n);
  in_front_.assign(n, false);
  magnitudes_.clear();
  for (std::size_t i = 0; i < n; ++i) {
    in_front_[i] = residual(i, reference_from_current, &errors_[i], &jacobians_[i]);
    if (!in_front_[i]) continue;
    magnitudes_.push_back(std::abs(errors_[i].x()));
    magnitudes_.push_back(std::abs(errors_[i].y()));
  }
  const std::size_t seen = magnitudes_.size() / 2;
  if (seen < 6) return 0;
  scale_px_ = std::max(kMadToSigma * medianInPlace(magnitudes_), min_scale_px);
  const double huber = kHuberNormScale * scale_px_;
  const double inverse_variance = 1.0 / (scale_px_ * scale_px_);
  for (std::size_t i = 0; i < n; ++i) {
    if (!in_front_[i]) continue;
    const double w = huberWeight(errors_[i].norm(), huber) * inverse_variance;
    H->noalias() += (w * jacobians_[i].transpose()) * jacobians_[i];
    g->noalias() += w * jacobians_[i].transpose() * errors_[i];
  }
  return seen;
}

}  // namespace cvo
