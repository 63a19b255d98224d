// The feature prior's inlier tracks as reprojection residuals of a motion, for the photometric
// stage to weigh beside its intensities (CvoParams::photometric_tracks).
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/StdVector>

#include "cvo_odometry/core/lie_group.hpp"
#include "cvo_odometry/core/motion_prior.hpp"

namespace cvo {

class TrackReprojection {
 public:
  // The prior's points live in the frame it tracked from, `prior_from_reference` away from the
  // reference the motion is solved against.
  TrackReprojection(const MotionPrior& prior, const Eigen::Isometry3d& prior_from_reference);

  std::size_t size() const { return points_.size(); }

  // Track i's error (px) where `reference_from_current` puts its point in the current image,
  // and its Jacobian for the left perturbation exp(xi) * reference_from_current, xi = [omega; v]
  // (the photometric stage's); false when the point falls behind the camera (or is not finite).
  bool residual(std::size_t i, const Eigen::Isometry3d& reference_from_current,
                Eigen::Vector2d* error, Eigen::Matrix<double, 2, 6>* jacobian) const;

  // Adds the tracks' normal equations (H += J^T W J, g += J^T W r) with Huber's weights (on the
  // error's length) over the variance of their own robust scale (MAD of the error components,
  // at least `min_scale_px`). Returns how many tracks were in front of the camera and added; 0,
  // adding nothing, when fewer than 6 are.
  std::size_t addNormalEquations(const Eigen::Isometry3d& reference_from_current,
                                 double min_scale_px, Matrix6d* H, Vector6d* g);

  double scalePx() const { return scale_px_; }  // of the last addNormalEquations; 0: none added

 private:
  std::vector<Eigen::Vector3d, Eigen::aligned_allocator<Eigen::Vector3d>> points_;  // reference
  std::vector<Eigen::Vector2d, Eigen::aligned_allocator<Eigen::Vector2d>> observations_;
  double focal_px_ = 0.0;
  double scale_px_ = 0.0;
  // Scratch of addNormalEquations.
  std::vector<Eigen::Vector2d, Eigen::aligned_allocator<Eigen::Vector2d>> errors_;
  std::vector<Eigen::Matrix<double, 2, 6>, Eigen::aligned_allocator<Eigen::Matrix<double, 2, 6>>>
      jacobians_;
  std::vector<bool> in_front_;
  std::vector<double> magnitudes_;
};

}  // namespace cvo
