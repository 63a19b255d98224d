// TrackReprojection: the feature tracks' reprojection errors the photometric stage weighs beside
// its intensities. Zero at the motion the tracks were made with, Jacobians that match finite
// differences, Gauss-Newton on them alone that finds the motion through noise and outliers, and
// nothing added without enough tracks in front of the camera.
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "cvo_odometry/core/lie_group.hpp"
#include "cvo_odometry/core/track_reprojection.hpp"

namespace {

struct Scene {
  cvo::MotionPrior prior;
  Eigen::Isometry3d prior_from_reference;
  Eigen::Isometry3d truth;  // reference <- current
};

// Points 3-40 m ahead of the prior's camera (a road scene), seen by the current camera under
// `truth`; observations with Gaussian noise of `noise_px` and every `outlier_every`-th track
// 25 px off.
Scene makeScene(double noise_px, int outlier_every) {
  Scene s;
  s.truth = cvo::lie::fromXyzRpy(0.05, -0.02, 1.1, 0.01, -0.02, 0.015);
  s.prior_from_reference = cvo::lie::fromXyzRpy(0.01, 0.0, -0.3, 0.0, 0.005, 0.0);
  s.prior.focal_px = 707.0;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> depth(3.0, 40.0), across(-0.6, 0.6);
  std::normal_distribution<double> noise(0.0, noise_px / s.prior.focal_px);
  const Eigen::Isometry3d current_from_prior = s.truth.inverse() * s.prior_from_reference.inverse();
  for (int i = 0; i < 300; ++i) {
    const double z = depth(random);
    const Eigen::Vector3d X(across(random) * z, 0.3 * across(random) * z, z);
    const Eigen::Vector3d seen = current_from_prior * X;
    Eigen::Vector2d observation = seen.head<2>() / seen.z();
    observation += Eigen::Vector2d(noise(random), noise(random));
    if (outlier_every > 0 && i % outlier_every == 0) {
      observation.x() += 25.0 / s.prior.focal_px;
    }
    s.prior.points.push_back(X);
    s.prior.observations.push_back(observation);
  }
  return s;
}

Eigen::Isometry3d leftStep(const cvo::Vector6d& xi, const Eigen::Isometry3d& T) {
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  step.linear() = cvo::lie::expSO3(xi.head<3>());
  step.translation() = xi.tail<3>();
  return step * T;
}

TEST(TrackReprojection, ZeroAtTheTruthWithJacobiansMatchingFiniteDifferences) {
  const Scene s = makeScene(0.0, 0);
  const cvo::TrackReprojection tracks(s.prior, s.prior_from_reference);
  ASSERT_EQ(tracks.size(), 300u);
  Eigen::Vector2d error;
  Eigen::Matrix<double, 2, 6> jacobian;
  for (std::size_t i = 0; i < tracks.size(); i += 37) {
    ASSERT_TRUE(tracks.residual(i, s.truth, &error, &jacobian));
    EXPECT_LT(error.norm(), 1e-9) << "track " << i;
  }
  const Eigen::Isometry3d off = s.truth * cvo::lie::fromXyzRpy(0.1, 0.05, -0.2, 0.01, 0.02, -0.01);
  constexpr double h = 1e-6;
  for (std::size_t i = 0; i < tracks.size(); i += 29) {
    ASSERT_TRUE(tracks.residual(i, off, &error, &jacobian));
    for (int k = 0; k < 6; ++k) {
      cvo::Vector6d xi = cvo::Vector6d::Zero();
      xi(k) = h;
      Eigen::Vector2d plus, minus;
      Eigen::Matrix<double, 2, 6> unused;
      ASSERT_TRUE(tracks.residual(i, leftStep(xi, off), &plus, &unused));
      ASSERT_TRUE(tracks.residual(i, leftStep(-xi, off), &minus, &unused));
      const Eigen::Vector2d numeric = (plus - minus) / (2.0 * h);
      EXPECT_LT((numeric - jacobian.col(k)).norm(), 1e-4 * (1.0 + numeric.norm()))
          << "track " << i << ", coordinate " << k;
    }
  }
}

TEST(TrackReprojection, GaussNewtonFindsTheMotionThroughNoiseAndOutliers) {
  // 0.3 px noise, every 10th track 25 px off: Huber at the MAD scale keeps the outliers small.
  const Scene s = makeScene(0.3, 10);
  cvo::TrackReprojection tracks(s.prior, s.prior_from_reference);
  Eigen::Isometry3d T = s.truth * cvo::lie::fromXyzRpy(0.3, -0.1, 0.4, 0.02, -0.03, 0.01);
  for (int it = 0; it < 30; ++it) {
    cvo::Matrix6d H = cvo::Matrix6d::Zero();
    cvo::Vector6d g = cvo::Vector6d::Zero();
    ASSERT_EQ(tracks.addNormalEquations(T, 0.05, &H, &g), 300u);
    T = leftStep(-H.ldlt().solve(g), T);
  }
  const Eigen::Isometry3d error = s.truth.inverse() * T;
  EXPECT_LT(error.translation().norm(), 0.02);
  EXPECT_LT(cvo::lie::rotationAngle(error.linear()) * 180.0 / M_PI, 0.02);
  EXPECT_GT(tracks.scalePx(), 0.25);  // the inliers' noise, not the outliers'
  EXPECT_LT(tracks.scalePx(), 0.45);
}

TEST(TrackReprojection, AddsNothingWithoutSixTracksInFront) {
  Scene s = makeScene(0.0, 0);
  s.prior.points.resize(5);
  s.prior.observations.resize(5);
  cvo::TrackReprojection few(s.prior, s.prior_from_reference);
  cvo::Matrix6d H = cvo::Matrix6d::Identity();
  cvo::Vector6d g = cvo::Vector6d::Zero();
  EXPECT_EQ(few.addNormalEquations(s.truth, 0.05, &H, &g), 0u);
  EXPECT_EQ(H, cvo::Matrix6d::Identity());
  EXPECT_TRUE(g.isZero(0.0));
  EXPECT_EQ(few.scalePx(), 0.0);
  // Turned away: every point behind the camera.
  const Scene all = makeScene(0.0, 0);
  cvo::TrackReprojection behind(all.prior, all.prior_from_reference);
  const Eigen::Isometry3d away = all.truth * cvo::lie::fromXyzRpy(0, 0, 0, 0, M_PI, 0);
  EXPECT_EQ(behind.addNormalEquations(away, 0.05, &H, &g), 0u);
  EXPECT_EQ(H, cvo::Matrix6d::Identity());
  EXPECT_TRUE(g.isZero(0.0));
  // A track that is not finite is left out, not summed.
  Scene broken = makeScene(0.0, 0);
  broken.prior.observations[3].x() = std::numeric_limits<double>::quiet_NaN();
  cvo::TrackReprojection some(broken.prior, broken.prior_from_reference);
  EXPECT_EQ(some.addNormalEquations(broken.truth, 0.05, &H, &g), 299u);
  EXPECT_TRUE(H.allFinite());
  EXPECT_TRUE(g.allFinite());
}

}  // namespace
