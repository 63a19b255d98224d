// Pose covariance on SE(3) against Monte-Carlo sampling: noisy motions composed along a path
// (through keyframe changes too) give the spread the adjoint propagation predicts, in the body
// frame and about the parent frame's axes, and seen through a base <- camera transform.
#include <gtest/gtest.h>

#include <random>

#include "cvo_odometry/core/lie_group.hpp"
#include "cvo_odometry/core/pose_covariance.hpp"

namespace {

using cvo::Matrix6d;
using cvo::Vector6d;

// exp of a [rho; phi] twist (the covariance convention) as the lie module's [phi; rho].
Eigen::Isometry3d expTranslationFirst(const Vector6d& xi) {
  Vector6d swapped;
  swapped << xi.tail<3>(), xi.head<3>();
  return cvo::lie::expSE3(swapped);
}

Vector6d logTranslationFirst(const Eigen::Isometry3d& T) {
  const Vector6d xi = cvo::lie::logSE3(T);
  Vector6d swapped;
  swapped << xi.tail<3>(), xi.head<3>();
  return swapped;
}

Eigen::Isometry3d motion(double rx, double ry, double rz, double tx, double ty, double tz) {
  return cvo::lie::fromXyzRpy(tx, ty, tz, rx, ry, rz);
}

// A motion noise with correlations, a few mm and tenths of a degree.
Matrix6d motionNoise(double scale) {
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Identity();
  A(0, 4) = 0.5, A(1, 3) = -0.3, A(2, 5) = 0.2;
  Vector6d sigma;
  sigma << 0.004, 0.003, 0.006, 0.004, 0.003, 0.002;
  return scale * scale * A * sigma.cwiseAbs2().asDiagonal() * A.transpose();
}

Matrix6d sampleCovariance(const std::vector<Vector6d>& samples) {
  Matrix6d c = Matrix6d::Zero();
  for (const auto& s : samples)
    c += s * s.transpose();
  return c / static_cast<double>(samples.size());
}

// Relative agreement of two covariances: largest entry error over the largest variance.
double mismatch(const Matrix6d& a, const Matrix6d& b) {
  return (a - b).cwiseAbs().maxCoeff() / b.diagonal().maxCoeff();
}

TEST(PoseCovariance, PropagationMatchesMonteCarloAlongAPathWithKeyframes) {
  // Keyframe 0 -> frames 1..4 registered to it; frame 4 becomes keyframe 1 -> frames 5..8.
  const std::vector<Eigen::Isometry3d> steps = {
      motion(0.02, -0.01, 0.05, 0.10, 0.02, 0.30), motion(-0.03, 0.04, 0.01, -0.05, 0.10, 0.20),
      motion(0.01, 0.02, -0.06, 0.20, -0.03, 0.25), motion(0.05, -0.02, 0.02, 0.00, 0.05, 0.30)};
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  const Matrix6d Q = motionNoise(1.0);
  const Eigen::LLT<Matrix6d> root(Q);
  const auto noise = [&] {
    Vector6d z;
    for (int k = 0; k < 6; ++k)
      z[k] = normal(rng);
    return Vector6d(root.matrixL() * z);
  };
  // Predicted: keyframe 1's pose covariance, then a frame registered to it.
  Eigen::Isometry3d keyframe = Eigen::Isometry3d::Identity();
  Matrix6d P = Matrix6d::Zero();
  Eigen::Isometry3d kf_motion = Eigen::Isometry3d::Identity();
  for (const auto& step : steps)
    kf_motion = kf_motion * step;  // keyframe 0 <- frame 4
  P = cvo::propagateCovariance(P, kf_motion, Q);
  keyframe = kf_motion;
  const Eigen::Isometry3d last = steps[0] * steps[1];  // keyframe 1 <- frame 6
  const Matrix6d predicted = cvo::propagateCovariance(P, last, Q);
  const Eigen::Isometry3d truth = keyframe * last;

  std::vector<Vector6d> body, parent;
  for (int n = 0; n < 20000; ++n) {
    const Eigen::Isometry3d kf = kf_motion * expTranslationFirst(noise());
    const Eigen::Isometry3d pose = kf * last * expTranslationFirst(noise());
    body.push_back(logTranslationFirst(truth.inverse() * pose));
    // About the parent's axes: position error in the parent frame, rotation error there.
    Vector6d e;
    e.head<3>() = pose.translation() - truth.translation();
    e.tail<3>() = cvo::lie::logSO3(pose.linear() * truth.linear().transpose());
    parent.push_back(e);
  }
  EXPECT_LT(mismatch(sampleCovariance(body), predicted), 0.05);
  EXPECT_LT(mismatch(sampleCovariance(parent), cvo::toParentAxes(truth, predicted)), 0.05);
  // The first-order sum this replaces (adding the motion covariances) misses the coupling of
  // rotation and lever arm: 12 % off here.
  Matrix6d summed = Q;
  summed += Q;
  EXPECT_GT(mismatch(cvo::toParentAxes(truth, summed), cvo::toParentAxes(truth, predicted)), 0.1);
}

TEST(PoseCovariance, ACameraMotionSeenFromTheBaseFrame) {
  const Eigen::Isometry3d B = motion(-M_PI / 2, 0.0, -M_PI / 2, 0.2, 0.0, 0.5);  // base <- camera
  const Eigen::Isometry3d M = motion(0.01, 0.03, -0.02, 0.05, 0.0, 0.3);         // camera motion
  const Matrix6d Q = motionNoise(2.0);
  const Matrix6d predicted = cvo::conjugatedCovariance(B, Q);
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  const Eigen::LLT<Matrix6d> root(Q);
  std::vector<Vector6d> samples;
  const Eigen::Isometry3d base_motion = B * M * B.inverse();
  for (int n = 0; n < 20000; ++n) {
    Vector6d z;
    for (int k = 0; k < 6; ++k)
      z[k] = normal(rng);
    const Eigen::Isometry3d noisy = M * expTranslationFirst(root.matrixL() * z);
    samples.push_back(logTranslationFirst(base_motion.inverse() * B * noisy * B.inverse()));
  }
  EXPECT_LT(mismatch(sampleCovariance(samples), predicted), 0.05);
  // And a left perturbation turned into a right one.
  const Matrix6d right = cvo::rightPerturbation(M, Q);
  samples.clear();
  for (int n = 0; n < 20000; ++n) {
    Vector6d z;
    for (int k = 0; k < 6; ++k)
      z[k] = normal(rng);
    const Eigen::Isometry3d noisy = expTranslationFirst(root.matrixL() * z) * M;
    samples.push_back(logTranslationFirst(M.inverse() * noisy));
  }
  EXPECT_LT(mismatch(sampleCovariance(samples), right), 0.05);
}

}  // namespace
