#include <gtest/gtest.h>

#include <cmath>

#include "cvo_odometry/core/evaluation_report.hpp"
#include "cvo_odometry/core/lie_group.hpp"
#include "cvo_odometry/core/trajectory_io.hpp"

namespace {

cvo::Trajectory fixtureGroundTruth() {
  return cvo::readTumTrajectory(std::string(CVO_TEST_DATA_DIR) + "/tum_fr1_xyz/groundtruth.txt");
}

}  // namespace

TEST(TrajectoryEvaluation, GroundTruthAgainstItselfIsZero) {
  const auto gt = fixtureGroundTruth();
  cvo::EvaluationOptions options;
  const auto r = cvo::evaluateTrajectory(gt, gt, options);
  EXPECT_EQ(r.associated_poses, gt.size());
  EXPECT_LT(r.ate.rmse, 1e-9);
  EXPECT_LT(r.rpe_frame.translation_rmse, 1e-12);
  EXPECT_LT(r.rpe_frame.rotation_rmse_deg, 1e-6);
  EXPECT_GT(r.rpe_delta.count, 0u);
  EXPECT_LT(r.rpe_delta.translation_rmse, 1e-12);
}

TEST(TrajectoryEvaluation, RigidlyMovedEstimateHasZeroAteAndRpe) {
  const auto gt = fixtureGroundTruth();
  const Eigen::Isometry3d offset =
      cvo::lie::expSE3((cvo::Vector6d() << 0.3, -0.2, 1.0, 5, -3, 2).finished());
  cvo::Trajectory moved;
  for (const auto& p : gt.poses())
    moved.append(p.stamp, offset * p.pose);
  const auto r = cvo::evaluateTrajectory(gt, moved, {});
  EXPECT_LT(r.ate.rmse, 1e-9);
  EXPECT_LT(r.rpe_frame.translation_rmse, 1e-9);
  EXPECT_LT(r.rpe_frame.rotation_rmse_deg, 1e-6);
}

TEST(TrajectoryEvaluation, OnePerturbedPoseErrsInBothOfItsPairs) {
  const auto gt = fixtureGroundTruth();
  // Perturb one pose by 1 cm along its x axis: the two pairs touching it err by 1 cm each.
  cvo::Trajectory est;
  for (std::size_t i = 0; i < gt.size(); ++i) {
    Eigen::Isometry3d pose = gt[i].pose;
    if (i == 100) pose.translate(Eigen::Vector3d(0.01, 0.0, 0.0));
    est.append(gt[i].stamp, pose);
  }
  const auto poses = cvo::associate(gt, est, 0.001, cvo::Association::kNearest);
  const auto rpe = cvo::computeRpeFrameToFrame(poses);
  const double pairs = static_cast<double>(rpe.count);
  EXPECT_NEAR(rpe.translation_rmse, std::sqrt(2.0 * 0.01 * 0.01 / pairs), 1e-9);
}

TEST(TrajectoryEvaluation, ConstantMotionErrorPerFrameIsRecoveredExactly) {
  // Synthetic 30 Hz straight track; the estimate adds 2 mm and 0.1 deg of error to every step.
  const double dt = 1.0 / 30.0;
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  step.translation() << 0.01, 0.0, 0.0;
  Eigen::Isometry3d err = Eigen::Isometry3d::Identity();
  err.translation() << 0.0, 0.002, 0.0;
  err.linear() = Eigen::AngleAxisd(0.1 * M_PI / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
  cvo::Trajectory gt, est;
  Eigen::Isometry3d g = Eigen::Isometry3d::Identity(), e = g;
  for (int i = 0; i < 60; ++i) {
    gt.append(i * dt, g);
    est.append(i * dt, e);
    g = g * step;
    e = e * step * err;
  }
  const auto poses = cvo::associate(gt, est, 0.001, cvo::Association::kNearest);
  const auto rpe = cvo::computeRpeFrameToFrame(poses);
  EXPECT_EQ(rpe.count, 59u);
  EXPECT_NEAR(rpe.translation_rmse, 0.002, 1e-12);
  EXPECT_NEAR(rpe.rotation_rmse_deg, 0.1, 1e-9);
  EXPECT_NEAR(rpe.translation_rate_rmse, 0.002 * 30.0, 1e-9);
  EXPECT_NEAR(rpe.rotation_rate_rmse_deg, 3.0, 1e-7);
  const auto delta = cvo::computeRpeFixedDelta(poses, 1.0);
  EXPECT_EQ(delta.count, 30u);  // i = 0..29 have a partner 30 frames later
  EXPECT_NEAR(delta.rotation_rmse_deg, 3.0, 1e-7);
}

TEST(TrajectoryEvaluation, AteOfANoisyTrackIsTheNoiseAfterAlignment) {
  const auto gt = fixtureGroundTruth();
  cvo::Trajectory est;
  for (std::size_t i = 0; i < gt.size(); ++i) {
    Eigen::Isometry3d pose = gt[i].pose;
    // +-3 mm alternating along world z, zero mean: ATE rmse is 3 mm.
    pose.pretranslate(Eigen::Vector3d(0.0, 0.0, (i % 2 ? 0.003 : -0.003)));
    est.append(gt[i].stamp, pose);
  }
  const auto ate = cvo::computeAte(cvo::associate(gt, est, 0.001, cvo::Association::kNearest));
  EXPECT_NEAR(ate.rmse, 0.003, 2e-5);
}

TEST(TrajectoryEvaluation, KittiDriftOfAScaledTrackIsTheScaleError) {
  // 1 m steps along x for 1000 m; the estimate's steps are 2 % long.
  cvo::Trajectory gt, est;
  Eigen::Isometry3d g = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  step.translation() << 1.0, 0.0, 0.0;
  Eigen::Isometry3d est_step = step;
  est_step.translation() << 1.02, 0.0, 0.0;
  Eigen::Isometry3d e = g;
  for (int i = 0; i <= 1000; ++i) {
    gt.append(i, g);
    est.append(i, e);
    g = g * step;
    e = e * est_step;
  }
  const auto poses = cvo::associate(gt, est, 0.1, cvo::Association::kNearest);
  // As in the KITTI devkit the segment ends at the first frame beyond 100 m (101 m here) and
  // its error is divided by the nominal 100 m: 2 % of 101 m over 100 m.
  const auto drift100 = cvo::computeKittiDrift(poses, {100.0});
  EXPECT_EQ(drift100.count, 90u);  // first = 0, 10, ..., 890 have a frame beyond +100 m
  EXPECT_NEAR(drift100.translation_percent, 2.02, 1e-9);
  EXPECT_NEAR(drift100.rotation_deg_per_m, 0.0, 1e-9);
  const auto drift = cvo::computeKittiDrift(poses, cvo::kittiDriftLengths());
  EXPECT_GT(drift.translation_percent, 2.0);
  EXPECT_LT(drift.translation_percent, 2.02 + 1e-9);
  const auto too_long = cvo::computeKittiDrift(poses, {5000.0});
  EXPECT_EQ(too_long.count, 0u);
}

TEST(TrajectoryEvaluation, NoOverlapInTimeIsAClearError) {
  const auto gt = fixtureGroundTruth();
  cvo::Trajectory est;
  est.append(1.0, Eigen::Isometry3d::Identity());
  est.append(2.0, Eigen::Isometry3d::Identity());
  EXPECT_THROW(cvo::evaluateTrajectory(gt, est, {}), std::runtime_error);
}
