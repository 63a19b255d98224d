// rostest node (dynamic_bag.test): a TUM sequence with a moving board composited into it
// (cvo_make_dynamic, the bench's "person" case) and the board's labels, played from a bag into
// the nodelet with the board's class ignored and lost_frame_policy publish_nothing. Checks that
// a moving object never produces a trusted wrong pose: every frame after the first is trusted,
// no published pose is off the ground truth's step from the pose before by more than 1 degree or
// more than max(half the step, 2 cm) (the silent-failure rule of bench/dynamic_table.sh), and no
// point of the ignored class reaches cloud/current.
// Parameters (private): ground_truth, frames (expected), timeout_s (a deadline reached only when
// something is broken), camera_frame, ignored_class, player (default /player).
// Nothing depends on the machine's speed: the bag is played paused and resumed once this node
// receives the nodelet's output, and paced by the nodelet's indicator (play_bag.launch pace).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <string>
#include <vector>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "cvo_odometry/CvoIndicator.h"
#include "cvo_odometry/core/trajectory_evaluation.hpp"
#include "cvo_odometry/core/trajectory_io.hpp"
#include "cvo_odometry/ros/ros_conversions.hpp"
#include "odometry_record.hpp"
#include "rostest_main.hpp"

namespace {

struct CloudSeen {
  double stamp = 0.0;
  std::size_t points = 0;
  bool labelled = false;
  std::size_t of_ignored_class = 0;
};

bool hasField(const sensor_msgs::PointCloud2& cloud, const std::string& name) {
  return std::any_of(cloud.fields.begin(), cloud.fields.end(),
                     [&](const sensor_msgs::PointField& f) { return f.name == name; });
}

// Proves: with labels of the moving board and its class ignored, the nodelet trusts every frame
// after the first, publishes no pose that is a silent failure, and leaves the board's class out
// of its clouds.
TEST(DynamicBag, LabelledMovingObjectNeverGivesATrustedWrongPose) {
  ros::NodeHandle nh, pnh("~");
  std::string gt_path, camera_frame, player;
  int frames = 0, ignored_class = 1;
  double timeout = 300.0;
  ASSERT_TRUE(pnh.getParam("ground_truth", gt_path));
  ASSERT_TRUE(pnh.getParam("frames", frames));
  ASSERT_TRUE(pnh.getParam("camera_frame", camera_frame));
  pnh.param("timeout_s", timeout, timeout);
  pnh.param("ignored_class", ignored_class, ignored_class);
  pnh.param<std::string>("player", player, "/player");

  cvo_test::OdometryRecord collected;
  collected.subscribe(nh);
  std::vector<CloudSeen> clouds;  // guarded by collected.mutex
  auto cloud_sub = nh.subscribe<sensor_msgs::PointCloud2>(
      "cloud/current", 100, [&](const sensor_msgs::PointCloud2::ConstPtr& msg) {
        CloudSeen seen;
        seen.stamp = msg->header.stamp.toSec();
        seen.points = static_cast<std::size_t>(msg->width) * msg->height;
        seen.labelled = hasField(*msg, "label");
        if (seen.labelled) {
          for (sensor_msgs::PointCloud2ConstIterator<std::uint16_t> label(*msg, "label");
               label != label.end(); ++label)
            seen.of_ignored_class += *label == ignored_class;
        }
        std::lock_guard<std::mutex> lock(collected.mutex);
        clouds.push_back(seen);
      });
  tf2_ros::Buffer tf_buffer;
  tf2_ros::TransformListener tf_listener(tf_buffer);

  // Connected to the nodelet's output (the cloud too: it publishes clouds only to listeners),
  // then resume the paused player.
  ASSERT_NO_FATAL_FAILURE(cvo_test::resumeWhenConnected(
      {&collected.odom_sub, &collected.indicator_sub, &cloud_sub}, player));

  // Until every frame's indicator came (the deadline is for a hang only).
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout);
  const auto done = [&] {
    std::lock_guard<std::mutex> lock(collected.mutex);
    return static_cast<int>(collected.indicators.size()) >= frames;
  };
  while (!done() && ros::ok() && ros::WallTime::now() < deadline)
    ros::WallDuration(0.05).sleep();
  // The last frame's odometry and cloud follow its indicator: wait for them too.
  const ros::WallTime settle = ros::WallTime::now() + ros::WallDuration(30.0);
  const auto published = [&] {
    std::lock_guard<std::mutex> lock(collected.mutex);
    const auto expected = static_cast<std::size_t>(
        std::count_if(collected.indicators.begin(), collected.indicators.end(),
                      [](const cvo_odometry::CvoIndicator& i) { return i.published; }));
    return collected.odometry.size() >= expected && clouds.size() >= expected;
  };
  while (!published() && ros::ok() && ros::WallTime::now() < settle)
    ros::WallDuration(0.05).sleep();

  std::lock_guard<std::mutex> lock(collected.mutex);
  ASSERT_EQ(static_cast<int>(collected.indicators.size()), frames) << "one indicator per frame";
  EXPECT_TRUE(collected.indicators.front().first_frame);
  std::vector<double> trusted_stamps;
  for (std::size_t k = 0; k < collected.indicators.size(); ++k) {
    const auto& indicator = collected.indicators[k];
    if (k > 0) {
      EXPECT_FALSE(indicator.first_frame) << "frame " << k;
      EXPECT_TRUE(indicator.trusted)
          << "frame " << k << " (" << indicator.state << ") not trusted: " << indicator.problem
          << (indicator.motion_split.empty() ? "" : "; ") << indicator.motion_split;
    }
    // publish_nothing: a pose for a trusted frame only.
    EXPECT_EQ(indicator.published, static_cast<bool>(indicator.trusted)) << "frame " << k;
    if (indicator.trusted) trusted_stamps.push_back(indicator.header.stamp.toSec());
  }
  ASSERT_EQ(collected.odometry.size(), trusted_stamps.size())
      << "an odometry message a trusted frame";

  // Camera poses: base poses composed with base <- camera (the bag's /tf_static).
  geometry_msgs::TransformStamped base_from_camera;
  ASSERT_NO_THROW(base_from_camera = tf_buffer.lookupTransform("base_link", camera_frame,
                                                               ros::Time(0), ros::Duration(5.0)));
  const Eigen::Isometry3d B = cvo::fromTransformMsg(base_from_camera.transform);
  cvo::Trajectory estimate;
  for (const auto& msg : collected.odometry) {
    EXPECT_NE(std::find(trusted_stamps.begin(), trusted_stamps.end(), msg.header.stamp.toSec()),
              trusted_stamps.end())
        << "a pose at " << msg.header.stamp << " for a frame not trusted";
    estimate.append(msg.header.stamp.toSec(), cvo::fromPoseMsg(msg.pose.pose) * B);
  }
  const cvo::Trajectory ground_truth = cvo::readTumTrajectory(gt_path);
  const cvo::AssociatedPoses poses =
      cvo::associate(ground_truth, estimate, 0.05, cvo::Association::kInterpolate);
  ASSERT_EQ(poses.size(), estimate.size()) << "ground truth at every published pose";
  // Each published pose against the one before (all trusted): the silent-failure rule.
  double worst_m = 0.0, worst_deg = 0.0;
  for (std::size_t k = 1; k < poses.size(); ++k) {
    const Eigen::Isometry3d truth = poses.ground_truth[k - 1].inverse() * poses.ground_truth[k];
    const Eigen::Isometry3d step = poses.estimate[k - 1].inverse() * poses.estimate[k];
    const Eigen::Isometry3d error = truth.inverse() * step;
    const double t = error.translation().norm();
    const double r = Eigen::AngleAxisd(error.rotation()).angle() * 180.0 / M_PI;
    worst_m = std::max(worst_m, t);
    worst_deg = std::max(worst_deg, r);
    EXPECT_FALSE(t > std::max(0.5 * truth.translation().norm(), 0.02) || r > 1.0)
        << "pose at " << poses.stamps[k] << " is a silent failure: " << 1000.0 * t << " mm and "
        << r << " deg off a step of " << 1000.0 * truth.translation().norm() << " mm";
  }
  std::cout << poses.size() << " poses; largest step error " << 1000.0 * worst_m << " mm, "
            << worst_deg << " deg\n";
  const cvo::SilentFailures silent = cvo::countSilentFailures(poses, trusted_stamps);
  EXPECT_EQ(silent.judged + 1, poses.size());
  EXPECT_EQ(silent.failures, 0u);

  // The board's class never reaches the cloud; the cloud carries labels.
  ASSERT_GE(clouds.size(), trusted_stamps.size()) << "a cloud a published frame";
  std::size_t ignored_points = 0;
  for (const CloudSeen& cloud : clouds) {
    EXPECT_TRUE(cloud.labelled) << "cloud at " << cloud.stamp << " has no label field";
    EXPECT_GT(cloud.points, 1000u) << "cloud at " << cloud.stamp;
    ignored_points += cloud.of_ignored_class;
  }
  EXPECT_EQ(ignored_points, 0u) << "points of the ignored class " << ignored_class
                                << " in cloud/current";
}

}  // namespace

int main(int argc, char** argv) {
  return cvo_test::runRosTests(argc, argv, "test_dynamic_bag");
}
