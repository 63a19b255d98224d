// The stereo topics subscribed and synchronized (exact or approximate): left|right/image_rect
// with left|right/camera_info, or left/image_rect, left/camera_info and a disparity image.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <vector>

#include <image_transport/image_transport.h>
#include <image_transport/subscriber_filter.h>
#include <message_filters/subscriber.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <stereo_msgs/DisparityImage.h>

#include "cvo_odometry/ros/policy_synchronizer.hpp"

namespace cvo {

class StereoTopicSync {
 public:
  // right and right_info are null with a disparity image, disparity null without.
  using Callback = std::function<void(
      const sensor_msgs::ImageConstPtr& left, const sensor_msgs::CameraInfoConstPtr& left_info,
      const sensor_msgs::ImageConstPtr& right, const sensor_msgs::CameraInfoConstPtr& right_info,
      const stereo_msgs::DisparityImageConstPtr& disparity)>;

  // `with_disparity`: subscribe `disparity` instead of the right image. Throws
  // std::invalid_argument for a policy stereo cannot use.
  StereoTopicSync(ros::NodeHandle nh, image_transport::ImageTransport& it,
                  const image_transport::TransportHints& hints, bool with_disparity,
                  SyncPolicy policy, int queue_size, double min_frame_interval, Callback callback);

  // Left images received, synchronized or not.
  std::size_t arrived() const { return arrived_; }

 private:
  void onImages(const sensor_msgs::ImageConstPtr& left,
                const sensor_msgs::CameraInfoConstPtr& left_info,
                const sensor_msgs::ImageConstPtr& right,
                const sensor_msgs::CameraInfoConstPtr& right_info) {
    callback_(left, left_info, right, right_info, nullptr);
  }
  void onDisparity(const sensor_msgs::ImageConstPtr& left,
                   const sensor_msgs::CameraInfoConstPtr& left_info,
                   const stereo_msgs::DisparityImageConstPtr& disparity) {
    callback_(left, left_info, nullptr, nullptr, disparity);
  }

  Callback callback_;
  std::atomic<std::size_t> arrived_{0};
  // Destroyed in reverse order: the synchronizer before the filters it is connected to.
  std::vector<std::shared_ptr<void>> filters_;
  std::shared_ptr<void> sync_;
};

}  // namespace cvo
