// rostest node: a bag played in a loop (rosbag play --loop --clock) into the nodelet, with a TF
// listener here as rviz or tf_echo has one. Each loop takes the clock back; the odometry restarts
// and its TF goes on, and no TF_REPEATED_DATA is logged: a listener clears its buffer when the
// clock goes back, so a transform stamped in the loop before and sent after the jump (a frame the
// nodelet was still working through) would stay and collide with the same stamp one loop later.
// The player is paced by the nodelet (play_bag.launch pace), so the nodelet is at most half a
// second of bag time behind: the frames it works through at the jump are the case this checks.
// Parameters (private): loops (how many times the odometry must have started), camera_frame.
#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <string>

#include <console_bridge/console.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <std_srvs/SetBool.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "cvo_odometry/CvoIndicator.h"
#include "rostest_main.hpp"

namespace {

// tf2 logs through console_bridge: count what it says about repeated stamps, print everything.
class TfLog : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel, const char* file, int line) override {
    if (text.find("TF_REPEATED_DATA") != std::string::npos) ++repeated;
    std::cerr << "tf2: " << text << " (" << file << ":" << line << ")\n";
  }
  std::atomic<int> repeated{0};
};

TEST(LoopingBag, RestartsEachLoopWithoutRepeatedTfData) {
  ros::NodeHandle nh, pnh("~");
  int loops = 3;
  pnh.param("loops", loops, loops);
  std::string camera_frame;
  ASSERT_TRUE(pnh.getParam("camera_frame", camera_frame));
  TfLog tf_log;
  console_bridge::useOutputHandler(&tf_log);
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);

  std::mutex mutex;
  int starts = 0, since_start = 0;
  ros::Time latest;
  auto indicator_sub = nh.subscribe<cvo_odometry::CvoIndicator>(
      "indicator", 100, [&](const cvo_odometry::CvoIndicator::ConstPtr& msg) {
        std::lock_guard<std::mutex> lock(mutex);
        if (msg->first_frame) ++starts, since_start = 0;
        ++since_start;
        if (msg->published) latest = msg->header.stamp;
      });
  const ros::WallTime connect_deadline = ros::WallTime::now() + ros::WallDuration(120.0);
  while (indicator_sub.getNumPublishers() == 0 && ros::WallTime::now() < connect_deadline)
    ros::WallDuration(0.1).sleep();
  ASSERT_GT(indicator_sub.getNumPublishers(), 0u);
  ASSERT_TRUE(ros::service::waitForService("/player/pause_playback", ros::Duration(120.0)));
  std_srvs::SetBool resume;
  resume.request.data = false;
  ASSERT_TRUE(ros::service::call("/player/pause_playback", resume));

  // Until the odometry started `loops` times and went a few frames into the last loop.
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(300.0);
  bool done = false;
  while (!done && ros::ok() && ros::WallTime::now() < deadline) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      done = starts >= loops && since_start >= 4;
    }
    ros::WallDuration(0.05).sleep();
  }
  ros::Time stamp;
  {
    std::lock_guard<std::mutex> lock(mutex);
    ASSERT_GE(starts, loops) << "the odometry did not restart at each loop";
    stamp = latest;
  }
  // TF went on in the last loop: the latest pose is there (the listener catches up).
  EXPECT_TRUE(buffer.canTransform("odom", "base_link", stamp, ros::Duration(30.0)))
      << "no odom -> base_link at " << stamp;
  // The bag's static camera transform is there too.
  EXPECT_TRUE(buffer.canTransform("base_link", camera_frame, ros::Time(0), ros::Duration(10.0)));
  EXPECT_EQ(tf_log.repeated, 0) << "TF_REPEATED_DATA logged";
  console_bridge::restorePreviousOutputHandler();
}

}  // namespace

int main(int argc, char** argv) {
  return cvo_test::runRosTests(argc, argv, "test_looping_bag");
}
