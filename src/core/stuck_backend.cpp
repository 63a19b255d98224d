#include "cvo_odometry/core/stuck_backend.hpp"

namespace cvo {

StuckBackend::StuckBackend(std::unique_ptr<RegistrationBackend> inner) : inner_(std::move(inner)) {}

void StuckBackend::setProblem(const LabeledCloud& target, const LabeledCloud&,
                              const CvoParams& params) {
  inner_->setProblem(target, target, params);  // the target against itself, aligned
}

void StuckBackend::useSubsets(const CloudSubsets& subsets) {
  CloudSubsets same = subsets;  // the source is the target: the same points of it
  same.source_stride = subsets.target_stride;
  same.source_count = 0;
  inner_->useSubsets(same);
}

kernels::MomentSums StuckBackend::moments(const Eigen::Isometry3d&, double ell) {
  return inner_->moments(Eigen::Isometry3d::Identity(), ell);
}

kernels::TaylorSums StuckBackend::taylor(const Eigen::Isometry3d&, const Vector6d& xi, double ell) {
  return inner_->taylor(Eigen::Isometry3d::Identity(), xi, ell);
}

kernels::CurvatureSums StuckBackend::curvature(const Eigen::Isometry3d&, double ell) {
  return inner_->curvature(Eigen::Isometry3d::Identity(), ell);
}

}  // namespace cvo
