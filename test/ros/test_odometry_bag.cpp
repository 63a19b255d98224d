// rostest node: a recorded bag of the fixture is played into the nodelet; this node collects its
// odometry and indicator messages and checks them against the fixture's ground truth.
// Parameters (private): ground_truth, ground_truth_times (KITTI), stamp_offset (s added to the
// ground truth's stamps, as cvo_make_bag does for KITTI), frames (expected), min_frames (fewest
// accepted, e.g. when a synchronization policy may drop a pair), max_final_error_m, max_rpe_m and
// max_rpe_deg (per frame) or max_rpe_mps and max_rpe_dps (per second), timeout_s (a generous
// deadline for all frames, reached only when something is broken), nearest_association, player
// (the rosbag player's name, default /player), camera_frame (base_link <- camera from TF turns
// the base poses into the camera's, which the ground truth has), runner_trajectory
// (cvo_run_sequence's trajectory of the same frames: the nodelet must give the same poses,
// within runner_tolerance_m), label_classes and ignored_class (segmentation on: the current
// debug cloud carries a label of fewer classes per point, more than one class, never the ignored
// one), late_tf_static_check (a TF listener started once the first frame is processed, long after
// the bag's /tf_static was played, still gets base_link <- camera: the bag latches it).
// Nothing here depends on the machine's speed: the bag is played paused (play_bag.launch
// start_paused) and resumed by this node only once it receives the nodelet's output, and paced
// by the nodelet's indicator (play_bag.launch pace), so no frame is missed or dropped however
// slowly the nodelet runs.
#include <gtest/gtest.h>

#include <mutex>

#include <set>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "cvo_odometry/CvoIndicator.h"
#include "cvo_odometry/core/evaluation_report.hpp"
#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/ros/ros_conversions.hpp"
#include "odometry_record.hpp"
#include "rostest_main.hpp"

namespace {

TEST(OdometryBag, TracksTheFixtureWithinBounds) {
  ros::NodeHandle nh, pnh("~");
  std::string gt_path, gt_times;
  int frames = 0, min_frames = 0;
  double offset = 0.0, max_final = 0.0, timeout = 60.0;
  double max_rpe_m = 1e9, max_rpe_deg = 1e9, max_rpe_mps = 1e9, max_rpe_dps = 1e9;
  ASSERT_TRUE(pnh.getParam("ground_truth", gt_path));
  pnh.param<std::string>("ground_truth_times", gt_times, "");
  ASSERT_TRUE(pnh.getParam("frames", frames));
  pnh.param("min_frames", min_frames, frames);
  pnh.param("stamp_offset", offset, 0.0);
  ASSERT_TRUE(pnh.getParam("max_final_error_m", max_final));
  pnh.param("max_rpe_m", max_rpe_m, max_rpe_m);
  pnh.param("max_rpe_deg", max_rpe_deg, max_rpe_deg);
  pnh.param("max_rpe_mps", max_rpe_mps, max_rpe_mps);
  pnh.param("max_rpe_dps", max_rpe_dps, max_rpe_dps);
  pnh.param("timeout_s", timeout, timeout);
  // Stereo preset: the photometric stage weighs the feature tracks on every tracked frame.
  bool expect_photometric_tracks = false;
  pnh.param("expect_photometric_tracks", expect_photometric_tracks, false);

  cvo_test::OdometryRecord collected;
  collected.subscribe(nh);
  sensor_msgs::PointCloud2 last_cloud;  // cloud/current, guarded by collected.mutex
  int label_classes = 0, ignored_class = -1;
  pnh.param("label_classes", label_classes, 0);
  pnh.param("ignored_class", ignored_class, -1);
  ros::Subscriber cloud_sub;
  if (label_classes > 0) {
    cloud_sub = nh.subscribe<sensor_msgs::PointCloud2>(
        "cloud/current", 5, [&](const sensor_msgs::PointCloud2::ConstPtr& msg) {
          std::lock_guard<std::mutex> lock(collected.mutex);
          last_cloud = *msg;
        });
  }
  tf2_ros::Buffer tf_buffer;
  tf2_ros::TransformListener tf_listener(tf_buffer);

  // Connected to the nodelet's output: then resume the paused player.
  std::string player, answer;
  pnh.param<std::string>("player", player, "/player");
  ASSERT_NO_FATAL_FAILURE(cvo_test::resumeWhenConnected(
      {&collected.odom_sub, &collected.indicator_sub}, player, &answer));
  std::cout << "player: " << answer << "\n";
  std::string camera_frame;
  ASSERT_TRUE(pnh.getParam("camera_frame", camera_frame));

  bool late_tf_static_check = false;
  pnh.param("late_tf_static_check", late_tf_static_check, false);
  if (late_tf_static_check) {
    const ros::WallTime first_deadline = ros::WallTime::now() + ros::WallDuration(timeout);
    auto processed = [&] {
      std::lock_guard<std::mutex> lock(collected.mutex);
      return !collected.indicators.empty();
    };
    while (!processed() && ros::ok() && ros::WallTime::now() < first_deadline)
      ros::WallDuration(0.05).sleep();
    ASSERT_TRUE(processed()) << "no frame processed";
    // Only a latched /tf_static reaches a listener this late (the bag plays it once, first);
    // the player is still running (paced by the nodelet, at most 0.5 s of bag time ahead).
    tf2_ros::Buffer late_buffer;
    tf2_ros::TransformListener late_listener(late_buffer);
    const ros::WallTime late_deadline = ros::WallTime::now() + ros::WallDuration(30.0);
    while (!late_buffer.canTransform("base_link", camera_frame, ros::Time(0)) &&
           ros::WallTime::now() < late_deadline)
      ros::WallDuration(0.05).sleep();
    EXPECT_TRUE(late_buffer.canTransform("base_link", camera_frame, ros::Time(0)))
        << "a listener started during playback did not get the bag's /tf_static";
  }

  // Until every frame came, or enough came and nothing more for 8 s (the bag has ended; only
  // where min_frames < frames, so a slow machine cannot make it fail).
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout);
  std::size_t seen = 0;
  ros::WallTime last_change = ros::WallTime::now();
  while (ros::ok() && ros::WallTime::now() < deadline) {
    {
      std::lock_guard<std::mutex> lock(collected.mutex);
      const std::size_t n = collected.indicators.size();
      if (static_cast<int>(n) >= frames) break;
      if (n != seen) seen = n, last_change = ros::WallTime::now();
      if (static_cast<int>(n) >= min_frames &&
          ros::WallTime::now() - last_change > ros::WallDuration(8.0))
        break;
    }
    ros::WallDuration(0.05).sleep();
  }
  std::lock_guard<std::mutex> lock(collected.mutex);
  ASSERT_GE(static_cast<int>(collected.indicators.size()), min_frames);
  ASSERT_LE(static_cast<int>(collected.indicators.size()), frames);
  ASSERT_EQ(collected.odometry.size(), collected.indicators.size()) << "one indicator per frame";
  EXPECT_TRUE(collected.indicators.front().first_frame);
  for (std::size_t k = 1; k < collected.indicators.size(); ++k) {
    const auto& indicator = collected.indicators[k];
    EXPECT_FALSE(indicator.first_frame) << "frame " << k;
    EXPECT_TRUE(indicator.converged) << "frame " << k << ": " << indicator.message;
    EXPECT_TRUE(indicator.trusted) << "frame " << k << " not tracked: " << indicator.problem;
    EXPECT_GT(indicator.iterations, 0);
    EXPECT_GT(indicator.cosine, 0.0);
    EXPECT_LE(indicator.cosine, 1.0 + 1e-9);
    EXPECT_GT(indicator.source_points, 1000u);
    EXPECT_GT(indicator.target_points, 1000u);
    if (expect_photometric_tracks) {
      EXPECT_TRUE(indicator.photometric_applied)
          << "frame " << k << ": " << indicator.photometric_skipped;
      EXPECT_GT(indicator.photometric_tracks, 20u) << "frame " << k;
    } else {
      EXPECT_EQ(indicator.photometric_tracks, 0u) << "frame " << k;
    }
  }
  if (label_classes > 0) {
    const auto& cloud = last_cloud;
    ASSERT_GT(cloud.width * cloud.height, 1000u) << "no current cloud received";
    std::set<int> classes;
    for (sensor_msgs::PointCloud2ConstIterator<std::uint16_t> label(cloud, "label");
         label != label.end(); ++label)
      classes.insert(*label);
    EXPECT_GT(classes.size(), 1u) << "the labels of more than one class reach the cloud";
    EXPECT_LT(*classes.rbegin(), label_classes);
    EXPECT_EQ(classes.count(ignored_class), 0u) << "ignore_classes drops class " << ignored_class;
  }
  const auto& last = collected.odometry.back();
  EXPECT_EQ(last.header.frame_id, "odom");
  EXPECT_EQ(last.child_frame_id, "base_link");
  EXPECT_GT(last.pose.covariance[0], 0.0) << "covariance filled in";

  // TF odom -> base_link available at the last stamp (waiting for the listener to catch up).
  EXPECT_TRUE(tf_buffer.canTransform("odom", "base_link", last.header.stamp, ros::Duration(60.0)));

  // The camera's poses: base poses composed with base <- camera (the bag's /tf_static).
  geometry_msgs::TransformStamped base_from_camera;
  ASSERT_NO_THROW(base_from_camera = tf_buffer.lookupTransform("base_link", camera_frame,
                                                               ros::Time(0), ros::Duration(5.0)));
  const Eigen::Isometry3d B = cvo::fromTransformMsg(base_from_camera.transform);
  cvo::Trajectory estimate;
  for (const auto& msg : collected.odometry)
    estimate.append(msg.header.stamp.toSec() - offset, cvo::fromPoseMsg(msg.pose.pose) * B);

  // The nodelet and the offline runner run the same pipeline: the same poses on the same frames.
  std::string runner_path;
  if (pnh.getParam("runner_trajectory", runner_path)) {
    double tolerance = 1e-6;
    pnh.param("runner_tolerance_m", tolerance, tolerance);
    const cvo::Trajectory runner =
        cvo::readTrajectory(runner_path, cvo::detectTrajectoryFormat(runner_path), gt_times);
    ASSERT_EQ(runner.size(), estimate.size());
    double largest = 0.0;
    for (std::size_t k = 0; k < runner.size(); ++k) {
      EXPECT_NEAR(runner[k].stamp, estimate[k].stamp, 1e-6);
      const Eigen::Isometry3d nodelet = estimate[0].pose.inverse() * estimate[k].pose;
      const Eigen::Isometry3d offline = runner[0].pose.inverse() * runner[k].pose;
      largest = std::max(largest, (nodelet.matrix() - offline.matrix()).cwiseAbs().maxCoeff());
    }
    std::cout << "largest difference from the runner's poses: " << largest << "\n";
    EXPECT_LT(largest, tolerance);
  }
  const cvo::Trajectory ground_truth =
      cvo::readTrajectory(gt_path, cvo::detectTrajectoryFormat(gt_path), gt_times);
  // Final pose relative to the first, against the ground truth's.
  auto truthAt = [&](double stamp, Eigen::Isometry3d* pose) {
    if (ground_truth.interpolate(stamp, 0.05, pose)) return true;
    const long k = ground_truth.nearest(stamp, 0.01);  // at the ends of a sparse ground truth
    if (k >= 0) *pose = ground_truth[static_cast<std::size_t>(k)].pose;
    return k >= 0;
  };
  Eigen::Isometry3d gt_first, gt_last;
  ASSERT_TRUE(truthAt(estimate[0].stamp, &gt_first));
  ASSERT_TRUE(truthAt(estimate[estimate.size() - 1].stamp, &gt_last));
  const Eigen::Isometry3d gt_motion = gt_first.inverse() * gt_last;
  const Eigen::Isometry3d est_motion =
      estimate[0].pose.inverse() * estimate[estimate.size() - 1].pose;
  const double final_error = (gt_motion.translation() - est_motion.translation()).norm();
  std::cout << "final position error " << final_error << " m over "
            << gt_motion.translation().norm() << " m\n";
  EXPECT_LT(final_error, max_final);

  cvo::EvaluationOptions options;
  bool nearest = false;  // KITTI ground truth: one pose per frame, no interpolation
  pnh.param("nearest_association", nearest, nearest);
  if (nearest) options.association = cvo::Association::kNearest;
  const auto report = cvo::evaluateTrajectory(ground_truth, estimate, options);
  cvo::printEvaluationReport(std::cout, report, options);
  EXPECT_LT(report.rpe_frame.translation_rmse, max_rpe_m);
  EXPECT_LT(report.rpe_frame.rotation_rmse_deg, max_rpe_deg);
  EXPECT_LT(report.rpe_frame.translation_rate_rmse, max_rpe_mps);
  EXPECT_LT(report.rpe_frame.rotation_rate_rmse_deg, max_rpe_dps);
}

}  // namespace

int main(int argc, char** argv) {
  return cvo_test::runRosTests(argc, argv, "test_odometry_bag");
}
