// The ROS layer without a master: every dynamic_reconfigure field is a settings-table row with
// the same default and range, the mapping both ways refuses what validate() refuses, README's
// parameter table is the table's, and the messages are built from a pipeline result as the
// nodelet publishes them.
#include <gtest/gtest.h>

#include <boost/any.hpp>
#include <fstream>
#include <sstream>

#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "cvo_odometry/core/lie_group.hpp"
#include "cvo_odometry/ros/event_rate.hpp"
#include "cvo_odometry/ros/frame_queue.hpp"
#include "cvo_odometry/ros/ros_conversions.hpp"
#include "cvo_odometry/ros/settings_reconfigure.hpp"

namespace {

using cvo_odometry::CvoOdometryConfig;

std::string anyText(const boost::any& value) {
  if (const auto* d = boost::any_cast<double>(&value)) return cvo::settingText(*d);
  if (const auto* i = boost::any_cast<int>(&value)) return cvo::settingText(*i);
  if (const auto* b = boost::any_cast<bool>(&value)) return cvo::settingText(*b);
  return boost::any_cast<std::string>(value);
}

double anyNumber(const boost::any& value) {
  if (const auto* d = boost::any_cast<double>(&value)) return *d;
  return static_cast<double>(boost::any_cast<int>(value));
}

TEST(RosSettings, EveryReconfigureFieldIsATableRowWithItsDefaultAndRange) {
  const auto rows = cvo::settingRows(cvo::NodeSettings());
  const auto& descriptions = CvoOdometryConfig::__getParamDescriptions__();
  ASSERT_GT(descriptions.size(), 20u);
  for (const auto& description : descriptions) {
    const auto row = std::find_if(rows.begin(), rows.end(),
                                  [&](const auto& r) { return r.name == description->name; });
    ASSERT_NE(row, rows.end()) << description->name << " is in the cfg but not the table";
    boost::any value;
    description->getValue(CvoOdometryConfig::__getDefault__(), value);
    EXPECT_EQ(anyText(value), row->value) << description->name << ": default";
    if (description->type == "double" || description->type == "int") {
      description->getValue(CvoOdometryConfig::__getMin__(), value);
      EXPECT_DOUBLE_EQ(anyNumber(value), row->min) << description->name << ": min";
      description->getValue(CvoOdometryConfig::__getMax__(), value);
      EXPECT_DOUBLE_EQ(anyNumber(value), row->max) << description->name << ": max";
    }
  }
}

TEST(RosSettings, ReconfigureMapsBothWaysAndRefusesNonsense) {
  cvo::NodeSettings settings;
  settings.odometry.cvo.ell_min = 0.03;
  settings.odometry.cvo.backend = cvo::BackendChoice::kCpu;
  const CvoOdometryConfig config = cvo::toConfig(settings);
  EXPECT_DOUBLE_EQ(config.ell_min, 0.03);
  EXPECT_EQ(config.backend, "cpu");
  const cvo::NodeSettings back = cvo::applyConfig(config, cvo::NodeSettings());
  EXPECT_EQ(cvo::describeSettings(back), cvo::describeSettings(settings));
  CvoOdometryConfig bad = config;
  bad.ell_init = 0.01;  // below ell_min
  EXPECT_THROW(cvo::applyConfig(bad, settings), std::invalid_argument);
  bad = config;
  bad.backend = "gpu";
  EXPECT_THROW(cvo::applyConfig(bad, settings), std::invalid_argument);
}

TEST(RosSettings, ReadmeCarriesTheGeneratedTable) {
  std::ifstream in(std::string(CVO_SOURCE_DIR) + "/README.md");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find(cvo::settingsMarkdown(cvo::NodeSettings())), std::string::npos)
      << "README's parameter table is out of date: run build/devel/lib/cvo_odometry/"
         "cvo_settings_table README.md";
}

TEST(RosConversions, OdometryMessageFromAnUpdate) {
  cvo::OdometryUpdate update;
  update.state = cvo::TrackingState::kTracking;
  update.frame_interval = 0.1;
  update.base_pose.translation() << 1.0, 2.0, 3.0;
  update.base_frame_motion.translation() << 0.05, 0.0, 0.0;
  update.base_frame_motion.linear() =
      Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  update.pose_covariance = cvo::Matrix6d::Identity() * 2e-4;
  update.twist_covariance = cvo::Matrix6d::Identity() * 3e-3;
  const nav_msgs::Odometry odom = cvo::odometryMsg(update, ros::Time(5.0), "odom", "base_link");
  EXPECT_EQ(odom.header.frame_id, "odom");
  EXPECT_EQ(odom.child_frame_id, "base_link");
  EXPECT_DOUBLE_EQ(odom.pose.pose.position.y, 2.0);
  EXPECT_NEAR(odom.twist.twist.linear.x, 0.5, 1e-12);
  EXPECT_NEAR(odom.twist.twist.angular.z, 0.1, 1e-12);
  EXPECT_DOUBLE_EQ(odom.pose.covariance[7], 2e-4);
  EXPECT_DOUBLE_EQ(odom.twist.covariance[35], 3e-3);
  const auto tf = cvo::odometryTransformMsg(odom);
  EXPECT_EQ(tf.child_frame_id, "base_link");
  EXPECT_DOUBLE_EQ(tf.transform.translation.z, 3.0);
}

TEST(RosConversions, IndicatorMessageFromAResult) {
  cvo::PipelineResult result;
  result.update.state = cvo::TrackingState::kLost;
  result.update.problem = "cosine 0.1 < min_cosine 0.5";
  result.update.stamp = 10.0;
  result.update.dt = 0.2;
  result.update.guess = cvo::GuessKind::kFeatures;
  result.update.attempts = 3;
  result.prior = cvo::MotionPrior();
  result.prior->inliers = 42;
  const auto msg = cvo::indicatorMsg(result, ros::Time(10.0), "odom", {12.5, 3});
  EXPECT_EQ(msg.state, "lost");
  EXPECT_FALSE(msg.trusted);
  EXPECT_EQ(msg.problem, result.update.problem);
  EXPECT_EQ(msg.guess, "features");
  EXPECT_EQ(msg.prior_inliers, 42u);
  EXPECT_EQ(msg.attempts, 3);
  EXPECT_DOUBLE_EQ(msg.reference_stamp, 9.8);
  EXPECT_DOUBLE_EQ(msg.latency_ms, 12.5);
  EXPECT_EQ(msg.dropped_frames, 3u);
  EXPECT_EQ(msg.photometric_tracks, 0u);

  // A stereo frame whose photometric stage weighed the feature tracks.
  result.update.state = cvo::TrackingState::kTracking;
  result.update.photometric.applied = true;
  result.update.photometric.correction_deg = 0.04;
  result.update.photometric.tracks = 271;
  const auto tracked = cvo::indicatorMsg(result, ros::Time(10.0), "odom", {});
  EXPECT_TRUE(tracked.photometric_applied);
  EXPECT_DOUBLE_EQ(tracked.photometric_correction_deg, 0.04);
  EXPECT_EQ(tracked.photometric_tracks, 271u);
}

TEST(RosConversions, FramesFromMessagesRefuseWhatTheyCannotRead) {
  sensor_msgs::Image image, depth;
  image.width = depth.width = 4;
  image.height = depth.height = 3;
  image.encoding = "bgr8";
  image.step = 12;
  image.data.assign(36, 100);
  depth.encoding = "32FC1";
  depth.step = 16;
  depth.data.assign(48, 0);
  sensor_msgs::CameraInfo info;
  info.width = 4, info.height = 3;
  info.K = {2, 0, 2, 0, 2, 1.5, 0, 0, 1};
  image.header.stamp = ros::Time(20.0);
  depth.header.stamp = ros::Time(19.985);
  const cvo::CameraFrame frame = cvo::rgbdFrameFromMsgs(image, info, depth, nullptr);
  EXPECT_EQ(std::get<cvo::RgbdFrame>(frame).image.cols, 4);
  // Depth 15 ms before colour: where a moving labelled object's depth lies (LabelTiming).
  EXPECT_NEAR(std::get<cvo::RgbdFrame>(frame).depth_after_colour, -0.015, 1e-6);
  image.encoding = "bgr16";
  EXPECT_THROW(cvo::rgbdFrameFromMsgs(image, info, depth, nullptr), std::invalid_argument);
  image.encoding = "bgr8";
  info.K[0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(cvo::rgbdFrameFromMsgs(image, info, depth, nullptr), std::invalid_argument);
  EXPECT_THROW(cvo::stereoFrameFromMsgs(image, info, nullptr, nullptr, nullptr),
               std::invalid_argument);
  // Stereo labels are the left image's; an encoding that is no class ids is refused (the
  // nodelet skips and counts the frame).
  info.K[0] = 2;
  sensor_msgs::CameraInfo right = info;
  info.P = {2, 0, 2, 0, 0, 2, 1.5, 0, 0, 0, 1, 0};
  right.P = {2, 0, 2, -0.2, 0, 2, 1.5, 0, 0, 0, 1, 0};
  sensor_msgs::Image labels = image;
  labels.encoding = "mono8";
  labels.step = 4;
  labels.data.assign(12, 3);
  const cvo::CameraFrame stereo =
      cvo::stereoFrameFromMsgs(image, info, &image, &right, nullptr, &labels);
  EXPECT_EQ(std::get<cvo::StereoFrame>(stereo).semantics.at<std::uint8_t>(2, 3), 3);
  EXPECT_NEAR(std::get<cvo::StereoFrame>(stereo).baseline, 0.1, 1e-12);
  labels.encoding = "rgb8";
  EXPECT_THROW(cvo::stereoFrameFromMsgs(image, info, &image, &right, nullptr, &labels),
               std::invalid_argument);
}

// Under simulated time the clock starts at the bag's time, decades after 0: the rate is judged
// from the first reading on, and only once a whole window has been watched.
TEST(EventRate, NoJudgementBeforeAWholeWindowThenTheRate) {
  cvo::EventRate rate;  // 5 s window, 1-100 Hz
  EXPECT_FALSE(rate.judge(0.0).warn) << "no clock yet (use_sim_time before /clock)";
  EXPECT_NE(rate.judge(0.0).message.find("no clock"), std::string::npos);
  const double start = 1305031102.175;  // the fixture's first stamp
  // A short bag: 37 frames at 30 Hz, judged every second of its time; never a verdict.
  for (int k = 0; k < 37; ++k) {
    const double now = start + k / 30.0;
    rate.tick(now);
    if (k % 30 == 0) {
      const auto judgement = rate.judge(now);
      EXPECT_FALSE(judgement.warn) << judgement.message;
      EXPECT_FALSE(judgement.measured);
      EXPECT_EQ(judgement.message.rfind("starting", 0), 0u) << judgement.message;
    }
  }
  // Frames at 30 Hz until a whole window has been watched: measured, within bounds.
  double now = start + 36 / 30.0;
  for (int k = 37; k < 200; ++k)
    rate.tick(now = start + k / 30.0);
  auto judgement = rate.judge(now);
  EXPECT_TRUE(judgement.measured);
  EXPECT_FALSE(judgement.warn) << judgement.message;
  EXPECT_NEAR(judgement.rate, 30.0, 0.5);
  // The odometry stops: too low, once the window holds nothing.
  judgement = rate.judge(now + 6.0);
  EXPECT_TRUE(judgement.warn);
  EXPECT_DOUBLE_EQ(judgement.rate, 0.0);
  EXPECT_NE(judgement.message.find("too low"), std::string::npos) << judgement.message;
  // A looping bag: time goes back to the start; measured afresh, no verdict meanwhile.
  rate.tick(start);
  judgement = rate.judge(start + 1.0);
  EXPECT_FALSE(judgement.warn) << judgement.message;
  EXPECT_NE(judgement.message.find("backwards"), std::string::npos) << judgement.message;
  EXPECT_EQ(judgement.events, 1u);
  // Far too many (a driver looping a frame as fast as it can): too high.
  cvo::EventRate fast;
  for (int k = 0; k <= 5000; ++k)
    fast.tick(100.0 + k * 0.001);
  EXPECT_TRUE(fast.judge(105.0).warn);
  EXPECT_NE(fast.judge(105.0).message.find("too high"), std::string::npos);
}

// Live: only the newest frame waits, except the first frames of a start, which are kept.
TEST(FrameQueue, KeptFramesWaitTheirTurnOthersAreReplaced) {
  cvo::FrameQueue<int> live(false);
  live.push(1, true);
  live.push(2, true);
  live.push(3);
  live.push(4);  // replaces 3, not the kept ones
  EXPECT_EQ(live.dropped(), 1u);
  EXPECT_EQ(live.waiting(), 3u);
  EXPECT_EQ(live.pop(), std::optional<int>(1));
  EXPECT_EQ(live.pop(), std::optional<int>(2));
  EXPECT_EQ(live.pop(), std::optional<int>(4));
  cvo::FrameQueue<int> replay(true);
  for (int k = 0; k < 4; ++k)
    replay.push(k);
  EXPECT_EQ(replay.dropped(), 0u);
  EXPECT_EQ(replay.waiting(), 4u);
}

// cvo_make_bag's bags (made at build time in test/bags) latch /tf_static, as rosbag records a
// static transform publisher's: rosbag play then latches it, so a listener started after playback
// began (rviz, tf_echo) still gets base_link -> camera.
TEST(MadeBags, TfStaticIsLatched) {
  for (const std::string name : {"tum_fr1_xyz.bag", "kitti_06.bag"}) {
    const std::string path = std::string(CVO_SOURCE_DIR) + "/test/bags/" + name;
    rosbag::Bag bag;
    ASSERT_NO_THROW(bag.open(path, rosbag::bagmode::Read))
        << path << ": made by the build's test bags (target cvo_test_bags)";
    rosbag::View view(bag, rosbag::TopicQuery("/tf_static"));
    const auto connections = view.getConnections();
    ASSERT_EQ(connections.size(), 1u) << name;
    const auto& header = *connections.front()->header;
    ASSERT_EQ(header.count("latching"), 1u) << name;
    EXPECT_EQ(header.at("latching"), "1") << name;
    EXPECT_EQ(header.at("type"), "tf2_msgs/TFMessage") << name;
    EXPECT_EQ(view.size(), 1u) << name;
  }
}

TEST(RosConversions, TheDefaultCameraLooksAlongTheBaseXAxis) {
  const Eigen::Isometry3d B = cvo::opticalFrameInBase();
  EXPECT_NEAR((B.linear() * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitX()).norm(), 0, 1e-12);
  EXPECT_NEAR((B.linear() * Eigen::Vector3d::UnitY() + Eigen::Vector3d::UnitZ()).norm(), 0, 1e-12);
  EXPECT_NEAR(B.linear().determinant(), 1.0, 1e-12);
}

}  // namespace
