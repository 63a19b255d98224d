#include <gtest/gtest.h>

#include <sstream>

#include "cvo_odometry/core/format_error.hpp"
#include "cvo_odometry/core/lie_group.hpp"
#include "cvo_odometry/core/trajectory_io.hpp"

namespace {

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const cvo::FormatError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(TrajectoryIo, ReadsTheTumFixtureGroundTruth) {
  const auto gt =
      cvo::readTumTrajectory(std::string(CVO_TEST_DATA_DIR) + "/tum_fr1_xyz/groundtruth.txt");
  ASSERT_GT(gt.size(), 300u);
  EXPECT_TRUE(gt.isTimeOrdered());
  EXPECT_NEAR(gt[0].stamp, 1305031101.1059, 1e-4);
  EXPECT_NEAR(gt[0].pose.translation().x(), 1.3704, 1e-9);
  // qw -0.3173 with a unit quaternion: rotation angle 2 acos(|qw|).
  EXPECT_NEAR(cvo::lie::rotationAngle(gt[0].pose.linear()), 2.0 * std::acos(0.3173), 1e-3);
}

TEST(TrajectoryIo, ReadsTheKittiFixtureWithTimes) {
  const std::string dir = std::string(CVO_TEST_DATA_DIR) + "/kitti_06_stereo/";
  const auto gt = cvo::readKittiTrajectory(dir + "poses.txt", dir + "times.txt");
  ASSERT_EQ(gt.size(), 8u);
  EXPECT_NEAR(gt[1].stamp, 0.1044989, 1e-9);
  EXPECT_TRUE(gt[0].pose.matrix().isIdentity(1e-6));
  EXPECT_EQ(cvo::detectTrajectoryFormat(dir + "poses.txt"), cvo::TrajectoryFormat::kKitti);
}

TEST(TrajectoryIo, TumRoundTrip) {
  cvo::Trajectory t;
  Eigen::Isometry3d pose =
      cvo::lie::expSE3((cvo::Vector6d() << 0.1, -0.2, 0.3, 1, 2, 3).finished());
  t.append(1305031102.175304, pose);
  t.append(1305031102.211214, pose * pose);
  std::stringstream ss;
  cvo::writeTumTrajectory(ss, t);
  const auto back = cvo::parseTumTrajectory(ss, "memory");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_NEAR(back[1].stamp, 1305031102.211214, 1e-6);
  EXPECT_LT((back[1].pose.matrix() - (pose * pose).matrix()).norm(), 1e-8);
}

TEST(TrajectoryIo, KittiRoundTrip) {
  cvo::Trajectory t;
  t.append(0, Eigen::Isometry3d::Identity());
  t.append(1, cvo::lie::expSE3((cvo::Vector6d() << 0.01, 0.02, -0.3, 4, 5, 6).finished()));
  std::stringstream ss;
  cvo::writeKittiTrajectory(ss, t);
  const auto back = cvo::parseKittiTrajectory(ss, "memory");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_LT((back[1].pose.matrix() - t[1].pose.matrix()).norm(), 1e-8);
}

TEST(TrajectoryIo, MalformedTumLinesNameTheLineAndTheExpectation) {
  std::stringstream few("# header\n1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 1\n");
  EXPECT_EQ(errorOf([&] { cvo::parseTumTrajectory(few, "gt.txt"); }),
            "gt.txt:3: expected 8 (timestamp tx ty tz qx qy qz qw), got 7 numbers");
  std::stringstream word("1.0 0 0 zero 0 0 0 1\n");
  EXPECT_EQ(errorOf([&] { cvo::parseTumTrajectory(word, "gt.txt"); }),
            "gt.txt:1: 'zero' is not a finite number");
  std::stringstream nan_value("1.0 0 0 nan 0 0 0 1\n");
  EXPECT_EQ(errorOf([&] { cvo::parseTumTrajectory(nan_value, "gt.txt"); }),
            "gt.txt:1: 'nan' is not a finite number");
  std::stringstream bad_q("1.0 0 0 0 0 0 0 2\n");
  EXPECT_NE(errorOf([&] { cvo::parseTumTrajectory(bad_q, "gt.txt"); }).find("gt.txt:1: quaternion"),
            std::string::npos);
  std::stringstream backwards("2.0 0 0 0 0 0 0 1\n1.0 0 0 0 0 0 0 1\n");
  EXPECT_NE(errorOf([&] {
              cvo::parseTumTrajectory(backwards, "gt.txt");
            }).find("gt.txt:2: timestamps must increase"),
            std::string::npos);
}

TEST(TrajectoryIo, MalformedKittiLinesNameTheLineAndTheExpectation) {
  std::stringstream few("1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1\n");
  EXPECT_EQ(errorOf([&] { cvo::parseKittiTrajectory(few, "poses.txt"); }),
            "poses.txt:2: expected 12 (3x4 pose, row-major), got 11 numbers");
  std::stringstream not_rotation("2 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_NE(errorOf([&] {
              cvo::parseKittiTrajectory(not_rotation, "poses.txt");
            }).find("poses.txt:1: the 3x3 part is not a rotation"),
            std::string::npos);
  std::stringstream two("1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_NE(errorOf([&] {
              cvo::parseKittiTrajectory(two, "poses.txt", {0.0});
            }).find("more poses than the 1 timestamps"),
            std::string::npos);
}

TEST(TrajectoryIo, MissingFileIsAnError) {
  EXPECT_THROW(cvo::readTumTrajectory("/nonexistent/gt.txt"), std::runtime_error);
  EXPECT_THROW(cvo::parseTrajectoryFormat("csv"), std::invalid_argument);
}

TEST(Trajectory, InterpolatesBetweenSamplesWithinTheGap) {
  cvo::Trajectory t;
  Eigen::Isometry3d a = Eigen::Isometry3d::Identity(), b = Eigen::Isometry3d::Identity();
  b.translation() << 1.0, 0.0, 0.0;
  b.linear() = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  t.append(10.0, a);
  t.append(10.01, b);
  Eigen::Isometry3d mid;
  ASSERT_TRUE(t.interpolate(10.0025, 0.02, &mid));
  EXPECT_NEAR(mid.translation().x(), 0.25, 1e-9);
  EXPECT_NEAR(cvo::lie::rotationAngle(mid.linear()), 0.05, 1e-9);
  EXPECT_FALSE(t.interpolate(9.0, 0.02, &mid));
  EXPECT_FALSE(t.interpolate(10.005, 0.004, &mid));
  EXPECT_EQ(t.nearest(10.008, 0.005), 1);
  EXPECT_EQ(t.nearest(11.0, 0.005), -1);
}
