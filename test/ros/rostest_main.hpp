// The main() of the rostest nodes: gtest with ROS callbacks served on two threads meanwhile.
#pragma once

#include <gtest/gtest.h>

#include <ros/ros.h>

namespace cvo_test {

inline int runRosTests(int argc, char** argv, const char* node_name) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, node_name);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  spinner.stop();
  ros::shutdown();
  return result;
}

}  // namespace cvo_test
