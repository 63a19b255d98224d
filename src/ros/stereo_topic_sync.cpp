#include "cvo_odometry/ros/stereo_topic_sync.hpp"

#include <algorithm>

#include <ros/console.h>
#include <boost/function.hpp>

namespace cvo {

StereoTopicSync::StereoTopicSync(ros::NodeHandle nh, image_transport::ImageTransport& it,
                                 const image_transport::TransportHints& hints,
                                 const StereoSyncOptions& options, Callback callback)
    : callback_(std::move(callback)), options_(options) {
  if (options.queue_size < 1) throw std::invalid_argument("queue_size must be >= 1");
  const int queue_size = options.queue_size;
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
  if (options.with_labels) {
    StampPairerOptions exact;
    exact.fixed_offset = 0.0;  // a segmentation image carries its left image's stamp
    exact.tolerance = 0.0;
    // Labels come later than the images (a segmentation network): room for a few frames.
    exact.queue_size = std::max<std::size_t>(static_cast<std::size_t>(queue_size), 20);
    labels_.emplace(exact);
  }
  auto left = image("left/image_rect");
  // Frames that arrive but never come out of the synchronizer are counted in diagnostics.
  left->registerCallback(boost::function<void(const sensor_msgs::ImageConstPtr&)>(
      [this](const sensor_msgs::ImageConstPtr& image) { countArrival(image->header.stamp); }));
  auto left_info = info("left/camera_info");
  if (!options.with_disparity) {
    auto right = image("right/image_rect");
    auto right_info = info("right/camera_info");
    sync_ = synchronize(options.policy, queue_size, options.min_frame_interval,
                        &StereoTopicSync::onImages, this, *left, *left_info, *right, *right_info);
  } else {
    auto disparity = std::make_shared<message_filters::Subscriber<stereo_msgs::DisparityImage>>(
        nh, "disparity", queue_size);
    filters_.push_back(disparity);
    sync_ = synchronize(options.policy, queue_size, options.min_frame_interval,
                        &StereoTopicSync::onDisparity, this, *left, *left_info, *disparity);
  }
  if (!labels_) return;
  labels_sub_ =
      it.subscribe("segmentation/image", static_cast<uint32_t>(queue_size),
                   boost::function<void(const sensor_msgs::ImageConstPtr&)>(
                       [this](const sensor_msgs::ImageConstPtr& labels) {
                         std::lock_guard<std::mutex> lock(labels_mutex_);
                         onLabelled(labels_->addSecond(labels->header.stamp.toSec(), labels));
                       }),
                   ros::VoidPtr(), hints);
}

void StereoTopicSync::countArrival(const ros::Time& stamp) {
  ++arrived_;
  // About three seconds of a 10 Hz stereo camera, or a whole queue: a partner topic is missing
  // or its stamps do not match (diagnostics count these as "frames not synchronized").
  const std::size_t limit =
      std::max<std::size_t>(30, static_cast<std::size_t>(options_.queue_size));
  if (++arrived_since_frame_ < limit) return;
  ROS_WARN_STREAM_THROTTLE(
      5.0, "cvo_odometry: " << arrived_since_frame_
                            << " left images in a row made no frame (latest stamp " << stamp
                            << "): are left/camera_info and "
                            << (options_.with_disparity ? "disparity"
                                                        : "right/image_rect, right/camera_info")
                            << (options_.with_labels ? " and segmentation/image" : "")
                            << " published, with the left image's stamp? sync_policy "
                            << settingText(options_.policy));
}

void StereoTopicSync::deliver(const Frame& frame) {
  arrived_since_frame_ = 0;
  callback_(frame);
}

void StereoTopicSync::onSet(Frame frame) {
  if (!labels_) {
    deliver(frame);
    return;
  }
  std::lock_guard<std::mutex> lock(labels_mutex_);
  const double stamp = frame.left->header.stamp.toSec();
  onLabelled(labels_->addFirst(stamp, std::move(frame)));
}

void StereoTopicSync::onLabelled(
    const std::vector<OrderedStampPairer<Frame, sensor_msgs::ImageConstPtr>::Pair>& frames) {
  for (const auto& pair : frames) {
    Frame frame = pair.first;
    frame.labels = pair.second;
    deliver(frame);
  }
}

}  // namespace cvo
