// What the bag-playing rostest nodes share: the nodelet's odom and indicator messages recorded as
// they arrive, and the start of a paused bag once the nodelet's output is connected.
#pragma once

#include <gtest/gtest.h>

#include <mutex>
#include <string>
#include <vector>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <std_srvs/SetBool.h>

#include "cvo_odometry/CvoIndicator.h"

namespace cvo_test {

struct OdometryRecord {
  std::mutex mutex;  // guards the messages, and what a test records beside them
  std::vector<nav_msgs::Odometry> odometry;
  std::vector<cvo_odometry::CvoIndicator> indicators;
  ros::Subscriber odom_sub, indicator_sub;

  // Subscribes odom and indicator (relative to `nh`), keeping every message.
  void subscribe(ros::NodeHandle& nh) {
    odom_sub = nh.subscribe<nav_msgs::Odometry>("odom", 100,
                                                [this](const nav_msgs::Odometry::ConstPtr& m) {
                                                  std::lock_guard<std::mutex> lock(mutex);
                                                  odometry.push_back(*m);
                                                });
    indicator_sub = nh.subscribe<cvo_odometry::CvoIndicator>(
        "indicator", 100, [this](const cvo_odometry::CvoIndicator::ConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex);
          indicators.push_back(*m);
        });
  }
};

// Waits (up to 120 s) until each of `subscribers` has a publisher, then resumes the rosbag player
// `player` (play_bag.launch start_paused; a player already running says so, which is fine) and
// puts its answer in `answer`. Fails the test, naming the topic, when a publisher never comes.
inline void resumeWhenConnected(const std::vector<const ros::Subscriber*>& subscribers,
                                const std::string& player, std::string* answer = nullptr) {
  const auto connected = [&] {
    for (const ros::Subscriber* s : subscribers)
      if (s->getNumPublishers() == 0) return false;
    return true;
  };
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(120.0);
  while (!connected() && ros::ok() && ros::WallTime::now() < deadline)
    ros::WallDuration(0.1).sleep();
  for (const ros::Subscriber* s : subscribers)
    ASSERT_GT(s->getNumPublishers(), 0u) << "no " << s->getTopic() << " publisher after 120 s";
  ASSERT_TRUE(ros::service::waitForService(player + "/pause_playback", ros::Duration(120.0)));
  std_srvs::SetBool resume;
  resume.request.data = false;
  ASSERT_TRUE(ros::service::call(player + "/pause_playback", resume));
  if (answer) *answer = resume.response.message;
}

}  // namespace cvo_test
