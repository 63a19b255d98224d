// The RGB-D topics (colour, depth, optional segmentation) subscribed and synchronized by the
// chosen policy: message_filters' exact or approximate policy, or the ordered pairing of colour
// and depth with a learned stamp offset (a segmentation image then pairs by its colour stamp).
// The ordered policy's first frames wait for the offset and then come together, flagged `held`.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include <image_transport/image_transport.h>
#include <image_transport/subscriber_filter.h>
#include <sensor_msgs/Image.h>

#include "cvo_odometry/frontend/ordered_stamp_pairer.hpp"
#include "cvo_odometry/ros/policy_synchronizer.hpp"

namespace cvo {

struct RgbdSyncOptions {
  SyncPolicy policy = SyncPolicy::kOrdered;
  int queue_size = 30;
  double min_frame_interval = 0.0;  // approximate: the frame period's lower bound (s), 0 unknown
  double tolerance = 0.0;           // ordered: the pairing tolerance (s), 0 automatic
  bool with_labels = false;         // subscribe segmentation/image too
};

class RgbdTopicSync {
 public:
  // Colour, depth and labels (null without segmentation), one frame at a time in stamp order;
  // `held`: one of the first frames, which waited for the ordered policy's stamp offset (a
  // live consumer should use it rather than replace it with the next).
  using Callback = std::function<void(const sensor_msgs::ImageConstPtr& image,
                                      const sensor_msgs::ImageConstPtr& depth,
                                      const sensor_msgs::ImageConstPtr& labels, bool held)>;

  // Subscribes rgb/image_rect_color, depth_registered/image_rect and, with labels,
  // segmentation/image through `it`. Throws std::invalid_argument for bad options.
  RgbdTopicSync(image_transport::ImageTransport& it, const image_transport::TransportHints& hints,
                const RgbdSyncOptions& options, Callback callback);

  // Colour images received, paired or not.
  std::size_t arrived() const { return arrived_; }
  // Ordered policy: the learned depth - colour stamp offset (s), once known.
  std::optional<double> learnedOffset() const;
  // Ordered policy: learn the offset again from the next frames (a reset); else nothing.
  void relearn();

 private:
  using ImagePtr = sensor_msgs::ImageConstPtr;
  struct ColourDepth {
    ImagePtr colour, depth;
    bool held = false;
  };

  void subscribeOrdered(image_transport::ImageTransport& it,
                        const image_transport::TransportHints& hints);
  void subscribeFilters(image_transport::ImageTransport& it,
                        const image_transport::TransportHints& hints);
  void onPairs(const std::vector<OrderedStampPairer<ImagePtr, ImagePtr>::Pair>& pairs);
  void onLabelledFrames(const std::vector<OrderedStampPairer<ColourDepth, ImagePtr>::Pair>& frames);
  void onSynchronized(const ImagePtr& image, const ImagePtr& depth) {
    deliver(image, depth, nullptr, false);
  }
  void onSynchronizedWithLabels(const ImagePtr& image, const ImagePtr& depth,
                                const ImagePtr& labels) {
    deliver(image, depth, labels, false);
  }
  void deliver(const ImagePtr& image, const ImagePtr& depth, const ImagePtr& labels, bool held);
  // A colour image arrived: warns when many in a row made no frame.
  void countArrival(const ros::Time& stamp);

  RgbdSyncOptions options_;
  Callback callback_;
  std::atomic<std::size_t> arrived_{0};
  std::atomic<std::size_t> arrived_since_frame_{0};
  std::atomic<double> offset_;  // NaN until learned
  std::size_t relearns_logged_ = 0;

  // Ordered policy: pairing and delivery under one lock, so frames leave in stamp order.
  std::mutex mutex_;
  std::optional<OrderedStampPairer<ImagePtr, ImagePtr>> colour_depth_;
  std::optional<OrderedStampPairer<ColourDepth, ImagePtr>> with_labels_;
  // Destroyed first (reverse order): no callback runs into a half-destroyed object.
  std::vector<image_transport::Subscriber> subscribers_;
  std::vector<std::shared_ptr<image_transport::SubscriberFilter>> filters_;
  std::shared_ptr<void> sync_;
};

}  // namespace cvo
