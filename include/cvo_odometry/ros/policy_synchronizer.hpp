// message_filters synchronizers chosen by policy at run time, and the policy names.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include <message_filters/simple_filter.h>
#include <message_filters/sync_policies/approximate_time.h>
#include <message_filters/sync_policies/exact_time.h>
#include <message_filters/synchronizer.h>
#include <ros/duration.h>

#include "cvo_odometry/core/settings_table.hpp"

namespace cvo {

// exact: equal stamps; approximate: message_filters' nearest-stamp policy; ordered: colour and
// depth paired in order with a learned stamp offset (RGB-D only, see OrderedStampPairer); auto:
// ordered for RGB-D, exact for stereo.
enum class SyncPolicy { kAuto, kExact, kApproximate, kOrdered };

inline const std::vector<EnumName<SyncPolicy>>& enumNames(SyncPolicy) {
  static const std::vector<EnumName<SyncPolicy>> names{{SyncPolicy::kAuto, "auto"},
                                                       {SyncPolicy::kExact, "exact"},
                                                       {SyncPolicy::kApproximate, "approximate"},
                                                       {SyncPolicy::kOrdered, "ordered"}};
  return names;
}

inline std::string toString(SyncPolicy policy) {
  return settingText(policy);
}

// A synchronizer of `filters` with the exact or approximate policy, calling `object->*method`.
// `frame_interval` > 0 tells the approximate policy that messages on one topic are at least that
// far apart, so it can pair messages whose stamps differ by up to half a frame.
template <class... M, class T>
std::shared_ptr<void> synchronize(SyncPolicy policy, int queue, double frame_interval,
                                  void (T::*method)(const boost::shared_ptr<const M>&...),
                                  T* object, message_filters::SimpleFilter<M>&... filters) {
  namespace sp = message_filters::sync_policies;
  if (policy == SyncPolicy::kApproximate) {
    using Sync = message_filters::Synchronizer<sp::ApproximateTime<M...>>;
    auto sync = std::make_shared<Sync>(sp::ApproximateTime<M...>(queue), filters...);
    if (frame_interval > 0.0) sync->setInterMessageLowerBound(ros::Duration(frame_interval));
    sync->registerCallback(method, object);
    return sync;
  }
  if (policy != SyncPolicy::kExact) {
    throw std::invalid_argument("sync_policy " + toString(policy) +
                                " is for colour and depth; use exact or approximate here");
  }
  using Sync = message_filters::Synchronizer<sp::ExactTime<M...>>;
  auto sync = std::make_shared<Sync>(sp::ExactTime<M...>(queue), filters...);
  sync->registerCallback(method, object);
  return sync;
}

}  // namespace cvo
