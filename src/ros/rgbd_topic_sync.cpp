#include "cvo_odometry/ros/rgbd_topic_sync.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <ros/console.h>
#include <boost/function.hpp>

namespace cvo {

RgbdTopicSync::RgbdTopicSync(image_transport::ImageTransport& it,
                             const image_transport::TransportHints& hints,
                             const RgbdSyncOptions& options, Callback callback)
    : options_(options),
      callback_(std::move(callback)),
      offset_(std::numeric_limits<double>::quiet_NaN()) {
  if (options_.queue_size < 1) throw std::invalid_argument("queue_size must be >= 1");
  if (options_.policy == SyncPolicy::kOrdered) {
    subscribeOrdered(it, hints);
  } else {
    subscribeFilters(it, hints);
  }
}

std::optional<double> RgbdTopicSync::learnedOffset() const {
  const double offset = offset_;
  return std::isnan(offset) ? std::nullopt : std::optional<double>(offset);
}

void RgbdTopicSync::relearn() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (colour_depth_) colour_depth_->relearn();
}

void RgbdTopicSync::deliver(const ImagePtr& image, const ImagePtr& depth, const ImagePtr& labels,
                            bool held) {
  arrived_since_frame_ = 0;
  callback_(image, depth, labels, held);
}

void RgbdTopicSync::countArrival(const ros::Time& stamp) {
  ++arrived_;
  // About a second of a 30 Hz camera, or a whole queue: a partner stream is missing or its
  // stamps do not match (diagnostics count these as "frames not synchronized").
  const std::size_t limit =
      std::max<std::size_t>(30, static_cast<std::size_t>(options_.queue_size));
  if (++arrived_since_frame_ < limit) return;
  const double offset = offset_;
  ROS_WARN_STREAM_THROTTLE(
      5.0, "cvo_odometry: " << arrived_since_frame_
                            << " colour images in a row made no frame (latest stamp " << stamp
                            << "): is depth_registered/image_rect"
                            << (options_.with_labels ? " (and segmentation/image)" : "")
                            << " published, with matching stamps? sync_policy "
                            << settingText(options_.policy)
                            << (std::isnan(offset) ? std::string()
                                                   : ", learned depth - colour offset " +
                                                         std::to_string(offset) + " s"));
}

void RgbdTopicSync::subscribeOrdered(image_transport::ImageTransport& it,
                                     const image_transport::TransportHints& hints) {
  StampPairerOptions pairing;
  pairing.tolerance = options_.tolerance;
  // Learning the offset needs a window of both streams, whatever the subscriber queues hold.
  pairing.queue_size = std::max<std::size_t>(static_cast<std::size_t>(options_.queue_size),
                                             4 * pairing.bootstrap_frames);
  colour_depth_.emplace(pairing);
  if (options_.with_labels) {
    StampPairerOptions exact = pairing;
    exact.fixed_offset = 0.0;  // a segmentation image carries its colour image's stamp
    exact.tolerance = 0.0;
    with_labels_.emplace(exact);
  }
  const auto queue = static_cast<uint32_t>(options_.queue_size);
  subscribers_.push_back(
      it.subscribe("rgb/image_rect_color", queue,
                   boost::function<void(const ImagePtr&)>([this](const ImagePtr& image) {
                     countArrival(image->header.stamp);
                     std::lock_guard<std::mutex> lock(mutex_);
                     onPairs(colour_depth_->addFirst(image->header.stamp.toSec(), image));
                   }),
                   ros::VoidPtr(), hints));
  subscribers_.push_back(
      it.subscribe("depth_registered/image_rect", queue,
                   boost::function<void(const ImagePtr&)>([this](const ImagePtr& depth) {
                     std::lock_guard<std::mutex> lock(mutex_);
                     onPairs(colour_depth_->addSecond(depth->header.stamp.toSec(), depth));
                   }),
                   ros::VoidPtr(), hints));
  if (!with_labels_) return;
  subscribers_.push_back(it.subscribe(
      "segmentation/image", queue,
      boost::function<void(const ImagePtr&)>([this](const ImagePtr& labels) {
        std::lock_guard<std::mutex> lock(mutex_);
        onLabelledFrames(with_labels_->addSecond(labels->header.stamp.toSec(), labels));
      }),
      ros::VoidPtr(), hints));
}

void RgbdTopicSync::onPairs(
    const std::vector<OrderedStampPairer<ImagePtr, ImagePtr>::Pair>& pairs) {
  if (colour_depth_->relearns() != relearns_logged_) {
    relearns_logged_ = colour_depth_->relearns();
    const double old = offset_;
    ROS_WARN_STREAM(
        "cvo_odometry: learning the depth - colour stamp offset again (a reset, "
        "time going backwards, or frames that stopped pairing"
        << (std::isnan(old) ? std::string() : " with the offset " + std::to_string(old) + " s")
        << "); the next frames wait for it, then all are used");
  }
  const auto offset = colour_depth_->offset();
  offset_ = offset ? *offset : std::numeric_limits<double>::quiet_NaN();
  for (const auto& pair : pairs) {
    if (!with_labels_) {
      deliver(pair.first, pair.second, nullptr, pair.held);
      continue;
    }
    onLabelledFrames(
        with_labels_->addFirst(pair.first_stamp, {pair.first, pair.second, pair.held}));
  }
}

void RgbdTopicSync::onLabelledFrames(
    const std::vector<OrderedStampPairer<ColourDepth, ImagePtr>::Pair>& frames) {
  for (const auto& frame : frames)
    deliver(frame.first.colour, frame.first.depth, frame.second, frame.first.held);
}

void RgbdTopicSync::subscribeFilters(image_transport::ImageTransport& it,
                                     const image_transport::TransportHints& hints) {
  auto image = [&](const std::string& topic) {
    filters_.push_back(
        std::make_shared<image_transport::SubscriberFilter>(it, topic, options_.queue_size, hints));
    return filters_.back();
  };
  auto rgb = image("rgb/image_rect_color");
  // Frames that arrive but never come out of the synchronizer are counted in diagnostics.
  rgb->registerCallback(boost::function<void(const ImagePtr&)>(
      [this](const ImagePtr& image) { countArrival(image->header.stamp); }));
  auto depth = image("depth_registered/image_rect");
  if (options_.with_labels) {
    auto labels = image("segmentation/image");
    sync_ = synchronize(options_.policy, options_.queue_size, options_.min_frame_interval,
                        &RgbdTopicSync::onSynchronizedWithLabels, this, *rgb, *depth, *labels);
  } else {
    sync_ = synchronize(options_.policy, options_.queue_size, options_.min_frame_interval,
                        &RgbdTopicSync::onSynchronized, this, *rgb, *depth);
  }
}

}  // namespace cvo
