// rostest node: drives the nodelet with real TUM frames published here (exact sync, segmentation
// on) and checks the live controls: segmentation wired into the clouds, dynamic_reconfigure
// changing ell_min for the next frame, a malformed frame skipped while later frames still give
// odometry, time going backwards and the reset service both restarting the odometry.
#include <gtest/gtest.h>

#include <mutex>

#include <cv_bridge/cv_bridge.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/image_encodings.h>
#include <std_srvs/Empty.h>
#include <opencv2/imgcodecs.hpp>

#include "cvo_odometry/CvoIndicator.h"
#include "cvo_odometry/frontend/tum_sequence.hpp"

namespace {

namespace enc = sensor_msgs::image_encodings;

class LiveControl : public testing::Test {
 protected:
  void SetUp() override {
    const cvo::TumSequence sequence(std::string(CVO_TEST_DATA_DIR) + "/tum_fr1_xyz");
    for (std::size_t k = 0; k < 8; ++k) {
      cv::Mat image, depth, metres;
      sequence.load(k, &image, &depth);
      depth.convertTo(metres, CV_32F, 1.0 / 5000.0);
      images_.push_back(image);
      depths_.push_back(metres);
    }
    rgb_pub_ = nh_.advertise<sensor_msgs::Image>("rgb/image_rect_color", 5);
    info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>("rgb/camera_info", 5, true);
    depth_pub_ = nh_.advertise<sensor_msgs::Image>("depth_registered/image_rect", 5);
    labels_pub_ = nh_.advertise<sensor_msgs::Image>("segmentation/image", 5);
    indicator_sub_ = nh_.subscribe<cvo_odometry::CvoIndicator>(
        "indicator", 20, [this](const cvo_odometry::CvoIndicator::ConstPtr& msg) {
          std::lock_guard<std::mutex> lock(mutex_);
          indicators_.push_back(*msg);
        });
    cloud_sub_ = nh_.subscribe<sensor_msgs::PointCloud2>(
        "cloud/current", 2, [this](const sensor_msgs::PointCloud2::ConstPtr& msg) {
          std::lock_guard<std::mutex> lock(mutex_);
          cloud_fields_.clear();
          for (const auto& f : msg->fields)
            cloud_fields_.push_back(f.name);
        });
    sensor_msgs::CameraInfo info;
    info.width = 640, info.height = 480;
    info.K = {517.3, 0, 318.6, 0, 516.5, 255.3, 0, 0, 1};
    info.P = {517.3, 0, 318.6, 0, 0, 516.5, 255.3, 0, 0, 0, 1, 0};
    info.header.frame_id = "camera_rgb_optical_frame";
    info_pub_.publish(info);
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(30.0);
    while ((depth_pub_.getNumSubscribers() == 0 || rgb_pub_.getNumSubscribers() == 0 ||
            labels_pub_.getNumSubscribers() == 0 || indicator_sub_.getNumPublishers() == 0 ||
            cloud_sub_.getNumPublishers() == 0) &&
           ros::WallTime::now() < deadline) {
      ros::WallDuration(0.1).sleep();
    }
    ros::WallDuration(1.0).sleep();  // the nodelet's camera_info subscriber too
  }

  // Publishes frame `k` stamped `stamp`; the depth may be given a wrong encoding.
  void publish(std::size_t k, double stamp, bool bad_depth = false) {
    std_msgs::Header header;
    header.stamp = ros::Time(stamp);
    header.frame_id = "camera_rgb_optical_frame";
    cv::Mat labels(480, 640, CV_8UC1, cv::Scalar(1));
    rgb_pub_.publish(cv_bridge::CvImage(header, enc::BGR8, images_[k]).toImageMsg());
    labels_pub_.publish(cv_bridge::CvImage(header, enc::MONO8, labels).toImageMsg());
    if (bad_depth) {
      cv::Mat bytes;
      depths_[k].convertTo(bytes, CV_8U, 50.0);
      depth_pub_.publish(cv_bridge::CvImage(header, enc::MONO8, bytes).toImageMsg());
    } else {
      depth_pub_.publish(cv_bridge::CvImage(header, enc::TYPE_32FC1, depths_[k]).toImageMsg());
    }
  }

  // Waits until `count` indicators arrived (or `timeout_s` passed); returns how many there are.
  std::size_t waitFor(std::size_t count, double timeout_s = 20.0) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout_s);
    while (ros::WallTime::now() < deadline) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (indicators_.size() >= count) return indicators_.size();
      }
      ros::WallDuration(0.05).sleep();
    }
    std::lock_guard<std::mutex> lock(mutex_);
    return indicators_.size();
  }

  cvo_odometry::CvoIndicator indicator(std::size_t k) {
    std::lock_guard<std::mutex> lock(mutex_);
    return indicators_.at(k);
  }

  ros::NodeHandle nh_;
  std::vector<cv::Mat> images_, depths_;
  ros::Publisher rgb_pub_, info_pub_, depth_pub_, labels_pub_;
  ros::Subscriber indicator_sub_, cloud_sub_;
  std::mutex mutex_;
  std::vector<cvo_odometry::CvoIndicator> indicators_;
  std::vector<std::string> cloud_fields_;
};

TEST_F(LiveControl, ReconfigureMalformedFramesTimeJumpAndReset) {
  const double t0 = 1000.0, dt = 1.0 / 30.0;
  publish(0, t0);
  ASSERT_EQ(waitFor(1), 1u);
  publish(1, t0 + dt);
  ASSERT_EQ(waitFor(2), 2u);
  EXPECT_TRUE(indicator(0).first_frame);
  EXPECT_FALSE(indicator(1).first_frame);
  EXPECT_TRUE(indicator(1).converged) << indicator(1).message;
  EXPECT_NEAR(indicator(1).final_lengthscale, 0.05, 1e-9);  // the preset's ell_min
  {
    std::lock_guard<std::mutex> lock(mutex_);
    EXPECT_NE(std::find(cloud_fields_.begin(), cloud_fields_.end(), "label"), cloud_fields_.end())
        << "segmentation labels in the debug cloud";
  }

  // dynamic_reconfigure: ell_min 0.05 -> 0.03, visible in the next report.
  dynamic_reconfigure::Reconfigure change;
  dynamic_reconfigure::DoubleParameter ell_min;
  ell_min.name = "ell_min";
  ell_min.value = 0.03;
  change.request.config.doubles.push_back(ell_min);
  ASSERT_TRUE(ros::service::call("cvo_odometry/set_parameters", change));
  publish(2, t0 + 2 * dt);
  ASSERT_EQ(waitFor(3), 3u);
  EXPECT_NEAR(indicator(2).final_lengthscale, 0.03, 1e-9);

  // A malformed frame (8-bit depth) is skipped; the next good frame still gives odometry.
  publish(3, t0 + 3 * dt, true);
  EXPECT_EQ(waitFor(4, 3.0), 3u) << "the malformed frame produced a report";
  publish(4, t0 + 4 * dt);
  ASSERT_EQ(waitFor(4), 4u);
  EXPECT_FALSE(indicator(3).first_frame) << "odometry continues after a skipped frame";

  // Time going backwards (a looping bag) restarts the odometry.
  publish(5, t0 - 10.0);
  ASSERT_EQ(waitFor(5), 5u);
  EXPECT_TRUE(indicator(4).first_frame);
  publish(6, t0 - 10.0 + dt);
  ASSERT_EQ(waitFor(6), 6u);
  EXPECT_FALSE(indicator(5).first_frame);

  // The reset service restarts it too.
  std_srvs::Empty reset;
  ASSERT_TRUE(ros::service::call("cvo_odometry/reset", reset));
  publish(7, t0 - 10.0 + 2 * dt);
  ASSERT_EQ(waitFor(7), 7u);
  EXPECT_TRUE(indicator(6).first_frame);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_live_control");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  spinner.stop();
  return result;
}
