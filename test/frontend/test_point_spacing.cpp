// PointSpacing and the front end's min_point_spacing: at most one point a cube, the first
// offered; on a real TUM frame brought near (its depth scaled down, as a close-range scene),
// the cloud keeps a subsequence of its points, one a cube, and on the frame as recorded nearly
// all of them.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <tuple>

#include <opencv2/core.hpp>

#include "cvo_odometry/frontend/odometry_settings.hpp"
#include "cvo_odometry/frontend/point_spacing.hpp"
#include "cvo_odometry/frontend/rgbd_cloud_builder.hpp"
#include "cvo_odometry/frontend/tum_sequence.hpp"

namespace {

TEST(PointSpacing, AdmitsTheFirstPointOfEachCube) {
  cvo::PointSpacing spacing(0.01, 8);
  EXPECT_TRUE(spacing.admit({0.001f, 0.002f, 1.003f}));
  EXPECT_FALSE(spacing.admit({0.009f, 0.008f, 1.001f}));  // the same cube
  EXPECT_TRUE(spacing.admit({0.011f, 0.002f, 1.003f}));   // the next one along x
  // Cubes are floor(coordinate / edge): -0.001 and 0.001 lie in different ones.
  EXPECT_TRUE(spacing.admit({-0.001f, 0.002f, 1.003f}));
  EXPECT_FALSE(spacing.admit({-0.009f, 0.009f, 1.009f}));
}

TEST(PointSpacing, ZeroSpacingFarAndNonFinitePointsAreAdmitted) {
  cvo::PointSpacing off(0.0, 4);
  for (int k = 0; k < 3; ++k)
    EXPECT_TRUE(off.admit({0.5f, 0.5f, 0.5f}));
  cvo::PointSpacing spacing(0.005, 8);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int k = 0; k < 2; ++k) {
    EXPECT_TRUE(spacing.admit({nan, 0.0f, 1.0f}));
    EXPECT_TRUE(spacing.admit({1e7f, 0.0f, 1.0f}));  // beyond 2^20 cubes: no cube to name
  }
}

TEST(PointSpacing, RefusesANegativeOrNonFiniteSpacing) {
  EXPECT_THROW(cvo::PointSpacing(-0.01, 4), std::invalid_argument);
  EXPECT_THROW(cvo::PointSpacing(std::numeric_limits<double>::quiet_NaN(), 4),
               std::invalid_argument);
  EXPECT_THROW(cvo::PointSpacing(std::numeric_limits<double>::infinity(), 4),
               std::invalid_argument);
}

std::tuple<long, long, long> cubeOf(const Eigen::Vector3f& p, double edge) {
  return {static_cast<long>(std::floor(p.x() / edge)), static_cast<long>(std::floor(p.y() / edge)),
          static_cast<long>(std::floor(p.z() / edge))};
}

struct SpacedClouds {
  cvo::LabeledCloud all, spaced;
  cvo::FrontendStats stats;
};

// TUM frame 5, its depth scaled by `depth_factor`, without and with a 5 mm spacing.
SpacedClouds buildFrame(double depth_factor) {
  const cvo::TumSequence sequence(std::string(CVO_TEST_DATA_DIR) + "/tum_fr1_xyz");
  cv::Mat image, depth;
  sequence.load(5, &image, &depth);
  cv::Mat scaled;
  depth.convertTo(scaled, CV_16U, depth_factor);
  cvo::RgbdFrontendOptions options;
  options.depth_units_per_metre = 5000.0;
  const cvo::RgbdFrame frame{image, scaled, cvo::tumIntrinsics("fr1", image.cols, image.rows),
                             cv::Mat()};
  SpacedClouds out;
  out.all = cvo::RgbdCloudBuilder(options).build(frame);
  options.cloud.min_point_spacing = 0.005;
  out.spaced = cvo::RgbdCloudBuilder(options).build(frame, &out.stats);
  return out;
}

TEST(PointSpacing, ANearFrameKeepsOnePointACubeInOrder) {
  const SpacedClouds near = buildFrame(0.35);  // the scene at 0.35x its depth: 0.2-1 m
  ASSERT_GT(near.all.size(), 5000u);
  EXPECT_EQ(near.spaced.size() + near.stats.spaced_out, near.all.size());
  // Selected on an image grid, over a fifth of the points share a 5 mm cube at this range
  // (29 %; 0.03 % of the recorded frames' points).
  EXPECT_GT(near.stats.spaced_out, near.all.size() / 5);
  std::set<std::tuple<long, long, long>> cubes;
  std::size_t next = 0;  // the kept points are the whole cloud's, in its order
  for (std::size_t i = 0; i < near.spaced.size(); ++i) {
    const Eigen::Vector3f p = near.spaced.position(i);
    EXPECT_TRUE(cubes.insert(cubeOf(p, 0.005)).second) << "point " << i;
    while (next < near.all.size() && near.all.position(next) != p)
      ++next;
    ASSERT_LT(next, near.all.size()) << "point " << i << " is not in the unspaced cloud's order";
    EXPECT_EQ(near.spaced.color(i)[0], near.all.color(next)[0]);
    ++next;
  }
  // The first point of every cube stays: each left-out point shares a kept point's cube.
  for (std::size_t i = 0; i < near.all.size(); ++i)
    EXPECT_TRUE(cubes.count(cubeOf(near.all.position(i), 0.005))) << "point " << i;
}

TEST(PointSpacing, TheRecordedFrameKeepsNearlyEveryPoint) {
  const SpacedClouds recorded = buildFrame(1.0);  // fr1_xyz at 0.6-2.5 m
  EXPECT_LT(recorded.stats.spaced_out, recorded.all.size() / 100);
  EXPECT_EQ(recorded.spaced.size() + recorded.stats.spaced_out, recorded.all.size());
}

TEST(PointSpacing, TheSettingIsAFractionOfEllMin) {
  cvo::OdometrySettings settings;
  EXPECT_DOUBLE_EQ(settings.cloudOptions().min_point_spacing,
                   settings.point_spacing * settings.cvo.ell_min);
  settings.cvo.ell_min = 0.05;
  settings.point_spacing = 0.5;
  EXPECT_DOUBLE_EQ(settings.cloudOptions().min_point_spacing, 0.025);
  settings.point_spacing = 0.0;
  EXPECT_EQ(settings.cloudOptions().min_point_spacing, 0.0);
  for (const double bad : {-0.1, 2.5, std::numeric_limits<double>::quiet_NaN()}) {
    settings.point_spacing = bad;
    EXPECT_THROW(settings.validate(), std::invalid_argument) << bad;
  }
}

}  // namespace
