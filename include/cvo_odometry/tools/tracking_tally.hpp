// Counts of the tracking states of a run, for the tools' summaries.
#pragma once

#include <iosfwd>
#include <map>

#include "cvo_odometry/core/frame_to_frame_odometry.hpp"

namespace cvo {

class TrackingTally {
 public:
  void add(TrackingState state) { ++counts_[state]; }
  // "tracking: T tracked, R recovered, L lost, S resets, F first frames" and a newline.
  void print(std::ostream& out) const;

 private:
  std::map<TrackingState, std::size_t> counts_;
};

}  // namespace cvo
