#include "cvo_odometry/core/registration_covariance.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

#include "cvo_odometry/core/lie_group.hpp"

namespace cvo {

Eigen::Matrix<double, 6, 6> registrationCovariance(const LabeledCloud& source,
                                                   const Eigen::Isometry3d& T, double lengthscale,
                                                   double cosine) {
  using Matrix6d = Eigen::Matrix<double, 6, 6>;
  const Matrix6d unknown = Matrix6d::Identity() * 1e6;
  if (source.size() < 3 || !(lengthscale > 0.0)) return unknown;
  // J = d(T p)/d(t, w) for a left perturbation: [I, -[Tp]x], so that the sum of J^T J over the
  // points is [[n I, -[s]x], [[s]x, (sum |p|^2) I - sum p p^T]] with s = sum p (p = T p): ten
  // sums instead of a 6x6 product per point.
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < source.size(); ++i) {
    const Eigen::Vector3d p = T * source.position(i).cast<double>();
    sum += p;
    scatter.noalias() += p * p.transpose();
  }
  Matrix6d information;
  information.topLeftCorner<3, 3>() =
      static_cast<double>(source.size()) * Eigen::Matrix3d::Identity();
  information.topRightCorner<3, 3>() = -lie::hat(sum);
  information.bottomLeftCorner<3, 3>() = lie::hat(sum);
  information.bottomRightCorner<3, 3>() = scatter.trace() * Eigen::Matrix3d::Identity() - scatter;
  information /= lengthscale * lengthscale;
  const Eigen::LDLT<Matrix6d> ldlt(information);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive() ||
      ldlt.vectorD().minCoeff() <= 1e-12 * ldlt.vectorD().maxCoeff()) {
    return unknown;
  }
  Matrix6d covariance = ldlt.solve(Matrix6d::Identity());
  covariance = 0.5 * (covariance + covariance.transpose());
  return covariance / std::clamp(cosine, 1e-3, 1.0);
}

Eigen::Matrix<double, 6, 6> guessedMotionCovariance(const CvoParams& params, double dt) {
  const double translation = params.max_linear_speed * dt;
  const double rotation = params.max_angular_speed * M_PI / 180.0 * dt;
  Eigen::Matrix<double, 6, 1> variances;
  variances << Eigen::Vector3d::Constant(translation * translation),
      Eigen::Vector3d::Constant(rotation * rotation);
  return variances.asDiagonal();
}

}  // namespace cvo
