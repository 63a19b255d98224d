// Test fixture for rostest nodes that drive the nodelet with real TUM frames published on its
// RGB-D topics (camera namespace) and collect what it publishes: indicators, odometry, the
// debug cloud's fields and diagnostics.
// It waits on events, never for a fixed time, so that a slow or loaded machine changes nothing
// but how long the test takes: connections (publisher and subscriber counts), the nodelet's
// acknowledgement of a camera_info (its "latest camera_info stamp" diagnostic), and counts
// (indicators, the "skipped frames" diagnostic). The waits have generous deadlines, reached only
// when something is broken. Publisher queues hold every frame a test sends, so none is dropped
// however slowly the nodelet takes them.
#pragma once

#include <gtest/gtest.h>

#include <cstdio>
#include <mutex>
#include <string>
#include <vector>

#include <cv_bridge/cv_bridge.h>
#include <diagnostic_msgs/DiagnosticArray.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/image_encodings.h>

#include "cvo_odometry/CvoIndicator.h"
#include "cvo_odometry/frontend/tum_sequence.hpp"
#include "odometry_record.hpp"

namespace cvo_test {

class TumTopicDriver : public testing::Test {
 protected:
  // Generous deadlines for events that take a few seconds at most on a loaded machine: reached
  // only when something is broken, so they cost nothing on a good run.
  static constexpr double kConnectTimeout = 120.0, kEventTimeout = 60.0;

  // Loads the fixture's frames `frames`, connects to the nodelet (segmentation topic too when
  // `segmentation`), and publishes a camera_info unless told not to. Call with
  // ASSERT_NO_FATAL_FAILURE.
  void connect(const std::vector<std::size_t>& frames, bool segmentation, bool camera_info = true) {
    const cvo::TumSequence sequence(std::string(CVO_TEST_DATA_DIR) + "/tum_fr1_xyz");
    for (std::size_t k : frames) {
      cv::Mat image, depth, metres;
      sequence.load(k, &image, &depth);
      depth.convertTo(metres, CV_32F, 1.0 / 5000.0);
      images_[k] = image;
      depths_[k] = metres;
    }
    rgb_pub_ = nh_.advertise<sensor_msgs::Image>("rgb/image_rect_color", kQueue);
    info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>("rgb/camera_info", kQueue, true);
    depth_pub_ = nh_.advertise<sensor_msgs::Image>("depth_registered/image_rect", kQueue);
    if (segmentation) labels_pub_ = nh_.advertise<sensor_msgs::Image>("segmentation/image", kQueue);
    record_.subscribe(nh_);
    cloud_sub_ = nh_.subscribe<sensor_msgs::PointCloud2>(
        "cloud/current", 2, [this](const sensor_msgs::PointCloud2::ConstPtr& msg) {
          std::lock_guard<std::mutex> lock(record_.mutex);
          cloud_fields_.clear();
          for (const auto& f : msg->fields)
            cloud_fields_.push_back(f.name);
        });
    diagnostics_sub_ = nh_.subscribe<diagnostic_msgs::DiagnosticArray>(
        "/diagnostics", 10, [this](const diagnostic_msgs::DiagnosticArray::ConstPtr& msg) {
          std::lock_guard<std::mutex> lock(record_.mutex);
          for (const auto& status : msg->status) {
            if (status.name.find("odometry") == std::string::npos) continue;
            for (const auto& kv : status.values)
              diagnostics_[kv.key] = kv.value;
          }
        });
    // Every connection up: the nodelet subscribed to what this node publishes (camera_info
    // included) and publishes what it subscribes to, diagnostics included.
    auto connected = [&] {
      return depth_pub_.getNumSubscribers() > 0 && rgb_pub_.getNumSubscribers() > 0 &&
             info_pub_.getNumSubscribers() > 0 &&
             (!segmentation || labels_pub_.getNumSubscribers() > 0) &&
             record_.indicator_sub.getNumPublishers() > 0 &&
             record_.odom_sub.getNumPublishers() > 0 && cloud_sub_.getNumPublishers() > 0 &&
             !diagnostic("frames").empty();
    };
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kConnectTimeout);
    while (!connected() && ros::ok() && ros::WallTime::now() < deadline)
      ros::WallDuration(0.1).sleep();
    ASSERT_TRUE(connected()) << "no connection to the nodelet after " << kConnectTimeout << " s";
    if (camera_info) {
      ASSERT_NO_FATAL_FAILURE(publishInfo(cameraInfo()));
    }
  }

  static sensor_msgs::CameraInfo cameraInfo() {
    sensor_msgs::CameraInfo info;
    info.width = 640, info.height = 480;
    info.K = {517.3, 0, 318.6, 0, 516.5, 255.3, 0, 0, 1};
    info.P = {517.3, 0, 318.6, 0, 0, 516.5, 255.3, 0, 0, 0, 1, 0};
    info.header.frame_id = "camera_rgb_optical_frame";
    return info;
  }

  // Publishes a camera_info (stamped 1, 2, 3, ... to tell them apart) and waits until the
  // nodelet reports it as its latest, so that the next frame uses it. Call with
  // ASSERT_NO_FATAL_FAILURE.
  void publishInfo(sensor_msgs::CameraInfo info) {
    info.header.stamp = ros::Time(static_cast<double>(++infos_));
    info_pub_.publish(info);
    char expected[32];
    std::snprintf(expected, sizeof expected, "%.3f", info.header.stamp.toSec());
    const std::string latest =
        diagnostic("latest camera_info stamp", [&](const std::string& v) { return v == expected; });
    ASSERT_EQ(latest, expected) << "the nodelet did not take the camera_info";
  }

  static std_msgs::Header header(double stamp) {
    std_msgs::Header h;
    h.stamp = ros::Time(stamp);
    h.frame_id = "camera_rgb_optical_frame";
    return h;
  }

  sensor_msgs::ImagePtr colour(std::size_t k, double stamp) const {
    return cv_bridge::CvImage(header(stamp), sensor_msgs::image_encodings::BGR8, images_.at(k))
        .toImageMsg();
  }
  sensor_msgs::ImagePtr depth(std::size_t k, double stamp) const {
    return cv_bridge::CvImage(header(stamp), sensor_msgs::image_encodings::TYPE_32FC1,
                              depths_.at(k))
        .toImageMsg();
  }

  // Publishes a colour and a depth image (and a one-class label image when segmentation is on).
  void publish(const sensor_msgs::ImagePtr& rgb, const sensor_msgs::ImagePtr& depth_image) {
    rgb_pub_.publish(rgb);
    if (labels_pub_) {
      const cv::Mat labels(480, 640, CV_8UC1, cv::Scalar(1));
      labels_pub_.publish(
          cv_bridge::CvImage(rgb->header, sensor_msgs::image_encodings::MONO8, labels)
              .toImageMsg());
    }
    depth_pub_.publish(depth_image);
  }
  void publish(std::size_t k, double stamp) { publish(colour(k, stamp), depth(k, stamp)); }

  // Waits until `count` indicators arrived (or `timeout_s` passed); returns how many there are.
  std::size_t waitFor(std::size_t count, double timeout_s = kEventTimeout) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
    while (ros::WallTime::now() < deadline) {
      {
        std::lock_guard<std::mutex> lock(record_.mutex);
        if (record_.indicators.size() >= count) return record_.indicators.size();
      }
      ros::WallDuration(0.05).sleep();
    }
    std::lock_guard<std::mutex> lock(record_.mutex);
    return record_.indicators.size();
  }

  cvo_odometry::CvoIndicator indicator(std::size_t k) {
    std::lock_guard<std::mutex> lock(record_.mutex);
    return record_.indicators.at(k);
  }
  std::vector<nav_msgs::Odometry> odometry() {
    std::lock_guard<std::mutex> lock(record_.mutex);
    return record_.odometry;
  }
  std::vector<std::string> cloudFields() {
    std::lock_guard<std::mutex> lock(record_.mutex);
    return cloud_fields_;
  }
  // Waits until the nodelet's diagnostics count `count` skipped frames (it publishes them once a
  // second); returns the count seen. A skipped frame never gives an indicator, so after this the
  // indicators show whether anything else was published.
  long waitForSkipped(long count) {
    const std::string skipped =
        diagnostic("skipped frames", [&](const std::string& v) { return std::stol(v) >= count; });
    return skipped.empty() ? 0 : std::stol(skipped);
  }

  // The latest value of a key of the nodelet's diagnostics ("" if not seen yet).
  std::string diagnostic(const std::string& key) {
    std::lock_guard<std::mutex> lock(record_.mutex);
    const auto it = diagnostics_.find(key);
    return it == diagnostics_.end() ? "" : it->second;
  }
  // The same, waiting up to `timeout_s` for one that satisfies `ready`.
  template <class Ready>
  std::string diagnostic(const std::string& key, Ready ready, double timeout_s = kEventTimeout) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
    std::string value;
    do {
      value = diagnostic(key);
      if (!value.empty() && ready(value)) break;
      ros::WallDuration(0.1).sleep();
    } while (ros::WallTime::now() < deadline);
    return value;
  }

  static constexpr int kQueue = 100;  // more than any test sends: nothing dropped when slow

  ros::NodeHandle nh_;
  int infos_ = 0;
  std::map<std::size_t, cv::Mat> images_, depths_;
  ros::Publisher rgb_pub_, info_pub_, depth_pub_, labels_pub_;
  ros::Subscriber cloud_sub_, diagnostics_sub_;
  OdometryRecord record_;  // odom and indicator; its mutex guards the members below too
  std::vector<std::string> cloud_fields_;
  std::map<std::string, std::string> diagnostics_;
};

}  // namespace cvo_test
