// Counts of the tracking states of a run, for the tools' summaries.
#pragma once

#include <iosfwd>
#include <map>

#include "cvo_odometry/frontend/odometry_pipeline.hpp"

namespace cvo {

class TrackingTally {
 public:
  void add(TrackingState state) { ++counts_[state]; }
  // A pipeline's frame: its state when processed, else counted as skipped or stale.
  void add(const PipelineResult& result);
  // "tracking: T tracked, R recovered, L lost, S resets, F first frames, K skipped, R stale"
  // and a newline.
  void print(std::ostream& out) const;

 private:
  std::map<TrackingState, std::size_t> counts_;
  std::size_t skipped_ = 0, stale_ = 0;
};

}  // namespace cvo
