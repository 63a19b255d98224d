// The stereo topics subscribed and synchronized (exact or approximate): left|right/image_rect
// with left|right/camera_info, or left/image_rect, left/camera_info and a disparity image; with
// segmentation, segmentation/image paired with them by the left image's stamp (as the RGB-D path
// pairs it by the colour image's).
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include <image_transport/image_transport.h>
#include <image_transport/subscriber_filter.h>
#include <message_filters/subscriber.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <stereo_msgs/DisparityImage.h>

#include "cvo_odometry/frontend/ordered_stamp_pairer.hpp"
#include "cvo_odometry/ros/policy_synchronizer.hpp"

namespace cvo {

struct StereoSyncOptions {
  bool with_disparity = false;  // subscribe `disparity` instead of the right image
  SyncPolicy policy = SyncPolicy::kExact;
  int queue_size = 5;
  double min_frame_interval = 0.0;  // approximate: the frame period's lower bound (s)
  bool with_labels = false;         // subscribe segmentation/image too
};

class StereoTopicSync {
 public:
  // One synchronized set: right and right_info are null with a disparity image, disparity null
  // without, labels null without segmentation.
  struct Frame {
    sensor_msgs::ImageConstPtr left;
    sensor_msgs::CameraInfoConstPtr left_info;
    sensor_msgs::ImageConstPtr right;
    sensor_msgs::CameraInfoConstPtr right_info;
    stereo_msgs::DisparityImageConstPtr disparity;
    sensor_msgs::ImageConstPtr labels;
  };
  using Callback = std::function<void(const Frame&)>;

  // Throws std::invalid_argument for a policy stereo cannot use.
  StereoTopicSync(ros::NodeHandle nh, image_transport::ImageTransport& it,
                  const image_transport::TransportHints& hints, const StereoSyncOptions& options,
                  Callback callback);

  // Left images received, synchronized or not.
  std::size_t arrived() const { return arrived_; }

 private:
  void onImages(const sensor_msgs::ImageConstPtr& left,
                const sensor_msgs::CameraInfoConstPtr& left_info,
                const sensor_msgs::ImageConstPtr& right,
                const sensor_msgs::CameraInfoConstPtr& right_info) {
    onSet({left, left_info, right, right_info, nullptr, nullptr});
  }
  void onDisparity(const sensor_msgs::ImageConstPtr& left,
                   const sensor_msgs::CameraInfoConstPtr& left_info,
                   const stereo_msgs::DisparityImageConstPtr& disparity) {
    onSet({left, left_info, nullptr, nullptr, disparity, nullptr});
  }
  // A synchronized set: delivered, or paired with its labels first.
  void onSet(Frame frame);
  void deliver(const Frame& frame);
  // A left image arrived: warns when many in a row made no frame.
  void countArrival(const ros::Time& stamp);
  void onLabelled(
      const std::vector<OrderedStampPairer<Frame, sensor_msgs::ImageConstPtr>::Pair>& frames);

  Callback callback_;
  StereoSyncOptions options_;
  std::atomic<std::size_t> arrived_{0};
  std::atomic<std::size_t> arrived_since_frame_{0};
  // Segmentation: sets and labels paired by equal stamps, under one lock.
  std::mutex labels_mutex_;
  std::optional<OrderedStampPairer<Frame, sensor_msgs::ImageConstPtr>> labels_;
  // Destroyed in reverse order: the synchronizer before the filters it is connected to, and
  // both before the pairer their callbacks reach.
  std::vector<std::shared_ptr<void>> filters_;
  std::shared_ptr<void> sync_;
  image_transport::Subscriber labels_sub_;
};

}  // namespace cvo
