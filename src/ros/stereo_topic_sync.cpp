#include "cvo_odometry/ros/stereo_topic_sync.hpp"

#include <boost/function.hpp>

namespace cvo {

StereoTopicSync::StereoTopicSync(ros::NodeHandle nh, image_transport::ImageTransport& it,
                                 const image_transport::TransportHints& hints, bool with_disparity,
                                 SyncPolicy policy, int queue_size, double min_frame_interval,
                                 Callback callback)
    : callback_(std::move(callback)) {
  auto image = [&](const std::string& topic) {
    auto filter = std::make_shared<image_transport::SubscriberFilter>(it, topic, queue_size, hints);
    filters_.push_back(filter);
    return filter;
  };
  auto info = [&](const std::string& topic) {
    auto filter = std::make_shared<message_filters::Subscriber<sensor_msgs::CameraInfo>>(
        nh, topic, queue_size);
    filters_.push_back(filter);
    return filter;
  };
  auto left = image("left/image_rect");
  // Frames that arrive but never come out of the synchronizer are counted in diagnostics.
  left->registerCallback(boost::function<void(const sensor_msgs::ImageConstPtr&)>(
      [this](const sensor_msgs::ImageConstPtr&) { ++arrived_; }));
  auto left_info = info("left/camera_info");
  if (!with_disparity) {
    auto right = image("right/image_rect");
    auto right_info = info("right/camera_info");
    sync_ = synchronize(policy, queue_size, min_frame_interval, &StereoTopicSync::onImages, this,
                        *left, *left_info, *right, *right_info);
    return;
  }
  auto disparity = std::make_shared<message_filters::Subscriber<stereo_msgs::DisparityImage>>(
      nh, "disparity", queue_size);
  filters_.push_back(disparity);
  sync_ = synchronize(policy, queue_size, min_frame_interval, &StereoTopicSync::onDisparity, this,
                      *left, *left_info, *disparity);
}

}  // namespace cvo
